#include "view/Viewer.h"

#include "io/ExrFile.h"
#include "io/OutputPaths.h"
#include "io/PngFile.h"
#include "render/ErrorMetrics.h"
#include "render/Progress.h"
#include "render/RenderSession.h"
#include "scene/SceneInputs.h"
#include "util/Error.h"
#include "view/CameraControl.h"
#include "view/DisplayPass.h"
#include "view/Swapchain.h"
#include "view/ViewerScript.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <optional>
#include <utility>

namespace vkrt {

namespace {

using Clock = std::chrono::steady_clock;

std::string g_glfwError;

void onGlfwError(int, const char* description) { g_glfwError = description ? description : "unknown GLFW error"; }

/// glfwInit / glfwTerminate, and the clear message when there is no display.
class GlfwSession {
public:
    GlfwSession()
    {
        glfwSetErrorCallback(onGlfwError);
        if (!glfwInit())
            throw std::runtime_error("cannot open a window: " + g_glfwError +
                                     "\n(no display? `vkrt render SCENE` renders without one)");
        if (!glfwVulkanSupported()) {
            glfwTerminate();
            throw std::runtime_error("GLFW finds no Vulkan loader for windows; `vkrt render SCENE` works without one");
        }
    }
    ~GlfwSession() { glfwTerminate(); }
    GlfwSession(const GlfwSession&) = delete;
    GlfwSession& operator=(const GlfwSession&) = delete;
};

class Window {
public:
    Window(uint32_t width, uint32_t height, const std::string& title)
    {
        glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
        m_window = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
        if (!m_window)
            throw std::runtime_error("cannot create a window: " + g_glfwError + " (`vkrt render SCENE` needs none)");
    }
    ~Window() { glfwDestroyWindow(m_window); }
    Window(const Window&) = delete;
    Window& operator=(const Window&) = delete;
    GLFWwindow* get() const { return m_window; }

private:
    GLFWwindow* m_window = nullptr;
};

PresentationSupport presentationFor(GLFWwindow* window)
{
    PresentationSupport support;
    uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    for (uint32_t i = 0; i < count; ++i) support.instanceExtensions.emplace_back(names[i]);
    support.createSurface = [window](VkInstance instance) {
        VkSurfaceKHR surface = VK_NULL_HANDLE;
        if (glfwCreateWindowSurface(instance, window, nullptr, &surface) != VK_SUCCESS)
            throw GpuError("cannot create a Vulkan surface for the window: " + g_glfwError);
        return surface;
    };
    return support;
}

/// Limits one display refresh's rendering to about this much time.
constexpr double kFrameSeconds = 1.0 / 30.0;

} // namespace

const char* viewerHelp()
{
    return "vkrt view keys:\n"
           "  left drag          orbit around the target   scroll  zoom (field of view)\n"
           "  left click         focus there (a camera with aperture_radius)\n"
           "  drop a file        open that scene (TOML, .gltf, .glb)\n"
           "  right button held  W A S D fly forward/left/back/right, Q E fly down/up\n"
           "  S                  save EXR + PNG            R       reset the accumulation\n"
           "  I                  switch whitted/path       P       pause\n"
           "  + -                exposure up/down          F       filmic tone curve on/off\n"
           "  H                  this list                 Esc     quit\n";
}

// In the file's own namespace, as the window types it holds are.
namespace {

/// The scene file and every file the scene read: what no file the viewer writes may replace.
std::vector<NamedFile> inputsOf(const Scene& scene)
{
    std::vector<NamedFile> inputs = filesTheSceneRead(scene);
    inputs.push_back({"the scene file", scene.path});
    return inputs;
}

/// The scene of `options`, refused before any window opens when one of the
/// session's `outputs` (--screenshot, a script's save and screenshot paths)
/// would replace a file it read: a texture, a glTF buffer, a mesh.
Scene loadSceneWritingNoInput(const ViewOptions& options, const std::vector<NamedFile>& outputs)
{
    Scene scene = loadScene(options.scenePath, {options.width, options.height}, options.gltf);
    const std::vector<NamedFile> inputs = inputsOf(scene);
    for (const NamedFile& output : outputs)
        refuseOverlappingFiles(inputs, {output}); // a script may write one file twice
    return scene;
}

/// All state of one viewer session. Members are declared in creation order.
class Viewer {
public:
    /// `outputs`: the files the session's script will write (checked against the scene's inputs).
    Viewer(const ViewOptions& options, const std::vector<NamedFile>& outputs);
    /// Runs `script` if it has commands, else the interactive loop.
    void run(const std::vector<ViewerCommand>& script);
    std::vector<std::string> validationMessages() const { return m_context.validationMessages(); }

private:
    ViewOptions m_options;
    Scene m_parsed; ///< as loaded (overrides applied) to size the window; then moved into the session
    GlfwSession m_glfw;
    Window m_window;
    VulkanContext m_context;
    std::unique_ptr<RenderSession> m_session;
    std::unique_ptr<DisplayPass> m_display;
    std::unique_ptr<Swapchain> m_swapchain;
    vk::raii::Semaphore m_imageAvailable = nullptr;
    vk::raii::Semaphore m_renderFinished = nullptr;
    vk::raii::Fence m_presented = nullptr;

    float m_exposure = 0.0f;
    bool m_filmic = false;
    bool m_paused = false;
    bool m_swapchainStale = false;
    BatchPacer m_pacer{kFrameSeconds}; ///< one display refresh holds about kFrameSeconds of rendering
    std::deque<std::string> m_keys;    ///< pressed keys not yet handled
    bool m_dragging = false;
    double m_lastX = 0, m_lastY = 0;
    double m_pressX = 0, m_pressY = 0;                       ///< where the left button went down
    std::optional<std::pair<double, double>> m_pendingFocus; ///< a click, as fractions of the window
    std::optional<std::string> m_pendingOpen;                ///< a scene file dropped on the window
    double m_pendingYaw = 0, m_pendingPitch = 0, m_pendingZoom = 1;
    Clock::time_point m_rateStart = Clock::now();
    uint64_t m_rateSamples = 0;
    double m_samplesPerSecond = 0;
    Clock::time_point m_lastTitle{};
    int m_saveCount = 0;

    const Scene& scene() const { return m_session->scene(); }
    const Renderer& renderer() const { return m_session->renderer(); }
    void createDisplay();
    void recreateSwapchain();
    void installCallbacks();
    void renderAndPresent(uint32_t frames);
    void present();
    bool handleKey(const std::string& key);
    bool flying() const { return glfwGetMouseButton(m_window.get(), GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS; }
    void applyCameraInput(double dt);
    void setCamera(const Camera& camera, const char* move);
    void focusAt(double fx, double fy);
    void openScene(const std::string& path);
    void updateTitle(bool force = false);
    void save(const std::string& exrPath);
    void screenshot(const std::string& pngPath);
    /// The displayed image to `pngPath`, and a line on standard output saying so (scripts, --screenshot).
    void screenshotAndSay(const std::string& pngPath);
    void runScript(const std::vector<ViewerCommand>& commands);
    void runInteractive();
};

} // namespace

SessionConfig sessionConfig(const ViewOptions& options, const Scene& scene)
{
    SessionConfig config;
    config.seed = options.seed;
    // A click focuses a thin lens at the depth the AOVs measure under it.
    config.aov = scene.camera.thinLens();
    config.variance.layer = options.variance;
    config.maxBandBytes = options.maxBandBytes;
    config.accel = options.accel;
    config.warmUp = false; // the first frames show at once
    return config;
}

Viewer::Viewer(const ViewOptions& options, const std::vector<NamedFile>& outputs)
    : m_options(options),
      m_parsed(loadSceneWritingNoInput(options, outputs)),
      m_window(m_parsed.camera.width, m_parsed.camera.height, "vkrt view - " + options.scenePath),
      m_context(ContextOptions{options.device, options.validation, presentationFor(m_window.get())}),
      m_exposure(options.exposure),
      m_filmic(options.filmic)
{
    SessionConfig config = sessionConfig(options, m_parsed);
    m_session = std::make_unique<RenderSession>(m_context, std::move(m_parsed), std::move(config));
    createDisplay();
    recreateSwapchain();
    m_imageAvailable = vk::raii::Semaphore(m_context.device(), vk::SemaphoreCreateInfo());
    m_renderFinished = vk::raii::Semaphore(m_context.device(), vk::SemaphoreCreateInfo());
    m_presented = vk::raii::Fence(m_context.device(), vk::FenceCreateInfo(vk::FenceCreateFlagBits::eSignaled));
    installCallbacks();
}

void Viewer::createDisplay()
{
    m_display = std::make_unique<DisplayPass>(m_context, renderer().accumulation(), renderer().bands());
}

void Viewer::recreateSwapchain()
{
    m_context.device().waitIdle();
    int width = 0, height = 0;
    glfwGetFramebufferSize(m_window.get(), &width, &height);
    while ((width == 0 || height == 0) && !glfwWindowShouldClose(m_window.get())) {
        glfwWaitEvents(); // minimized: nothing to present to
        glfwGetFramebufferSize(m_window.get(), &width, &height);
    }
    m_swapchain.reset();
    m_swapchain = std::make_unique<Swapchain>(m_context, vk::Extent2D(uint32_t(width), uint32_t(height)));
    m_swapchainStale = false;
}

void Viewer::installCallbacks()
{
    GLFWwindow* w = m_window.get();
    glfwSetWindowUserPointer(w, this);
    glfwSetFramebufferSizeCallback(w, [](GLFWwindow* window, int, int) {
        static_cast<Viewer*>(glfwGetWindowUserPointer(window))->m_swapchainStale = true;
    });
    glfwSetCharCallback(w, [](GLFWwindow* window, unsigned codepoint) {
        auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
        if (codepoint < 128) self->m_keys.emplace_back(1, char(std::toupper(int(codepoint))));
    });
    glfwSetMouseButtonCallback(w, [](GLFWwindow* window, int button, int action, int) {
        auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
        if (button != GLFW_MOUSE_BUTTON_LEFT) return;
        self->m_dragging = action == GLFW_PRESS;
        glfwGetCursorPos(window, &self->m_lastX, &self->m_lastY);
        if (action == GLFW_PRESS) self->m_pressX = self->m_lastX, self->m_pressY = self->m_lastY;
        // A click that did not drag: focus where it points.
        int width = 0, height = 0;
        glfwGetWindowSize(window, &width, &height);
        if (action == GLFW_RELEASE && std::hypot(self->m_lastX - self->m_pressX, self->m_lastY - self->m_pressY) < 3 &&
            width > 0 && height > 0)
            self->m_pendingFocus = std::make_pair(self->m_lastX / width, self->m_lastY / height);
    });
    glfwSetCursorPosCallback(w, [](GLFWwindow* window, double x, double y) {
        auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(window));
        if (!self->m_dragging) return;
        self->m_pendingYaw -= 0.3 * (x - self->m_lastX);
        self->m_pendingPitch += 0.3 * (y - self->m_lastY);
        self->m_lastX = x, self->m_lastY = y;
    });
    glfwSetDropCallback(w, [](GLFWwindow* window, int count, const char** paths) {
        if (count > 0) static_cast<Viewer*>(glfwGetWindowUserPointer(window))->m_pendingOpen = std::string(paths[0]);
    });
    glfwSetScrollCallback(w, [](GLFWwindow* window, double, double dy) {
        static_cast<Viewer*>(glfwGetWindowUserPointer(window))->m_pendingZoom *= std::pow(0.9, dy);
    });
}

/// A move the scene parser would refuse (a camera at its target, a field of
/// view of 0) is ignored with a message: the view stays as it was.
void Viewer::setCamera(const Camera& camera, const char* move)
{
    m_context.device().waitIdle();
    if (auto problem = m_session->moveCamera(camera))
        std::fprintf(stderr, "vkrt view: %s ignored: the camera would be invalid (%s)\n", move, problem->c_str());
}

/// Replaces the scene with the one in `path` (a TOML scene, or a glTF file
/// dropped on the window) at the window's image size; a file vkrt refuses
/// leaves the view as it was, with the reason.
void Viewer::openScene(const std::string& path)
{
    std::optional<Scene> scene;
    try {
        scene = loadScene(path, {renderer().width(), renderer().height()});
    } catch (const InputError& e) {
        std::fprintf(stderr, "vkrt view: cannot open %s: %s\n", path.c_str(), e.what());
        return;
    }
    m_context.device().waitIdle();
    m_display.reset(); // it reads the old renderer's accumulation buffer
    SessionConfig config = sessionConfig(m_options, *scene);
    m_session = std::make_unique<RenderSession>(m_context, std::move(*scene), std::move(config));
    createDisplay();
    glfwSetWindowTitle(m_window.get(), ("vkrt view - " + path).c_str());
    std::printf("vkrt view: opened %s\n", path.c_str());
    std::fflush(stdout);
}

/// Focuses the thin lens on the surface at (fx, fy) (fractions of the image):
/// the mean camera-space depth of the first hits there, from the AOVs.
void Viewer::focusAt(double fx, double fy)
{
    if (!scene().camera.thinLens()) {
        std::fprintf(stderr, "vkrt view: focus ignored: the camera is a pinhole (give it an aperture_radius)\n");
        return;
    }
    m_context.device().waitIdle();
    const uint32_t x = std::min(uint32_t(std::max(fx, 0.0) * renderer().width()), renderer().width() - 1);
    const uint32_t y = std::min(uint32_t(std::max(fy, 0.0) * renderer().height()), renderer().height() - 1);
    const float depth = renderer().aovs().depth[size_t(y) * renderer().width() + x];
    if (!std::isfinite(depth) || !(depth > 0)) {
        std::fprintf(stderr, "vkrt view: focus ignored: nothing is seen at pixel %u,%u yet\n", x, y);
        return;
    }
    Camera camera = scene().camera;
    camera.focusDistance = double(depth);
    setCamera(camera, "focus");
    std::printf("vkrt view: focus distance %.6g (pixel %u,%u)\n", double(depth), x, y);
    std::fflush(stdout);
}

void Viewer::applyCameraInput(double dt)
{
    GLFWwindow* w = m_window.get();
    auto held = [&](int key) { return glfwGetKey(w, key) == GLFW_PRESS ? 1.0 : 0.0; };
    // Flying needs the right button held, so that S alone can save.
    double speed = flying() ? 0.6 * dt : 0.0;
    double right = (held(GLFW_KEY_D) - held(GLFW_KEY_A)) * speed;
    double up = (held(GLFW_KEY_E) - held(GLFW_KEY_Q)) * speed;
    double forward = (held(GLFW_KEY_W) - held(GLFW_KEY_S)) * speed;
    Camera camera = scene().camera;
    bool changed = false;
    if (right != 0 || up != 0 || forward != 0) camera = fly(camera, right, up, forward), changed = true;
    if (m_pendingYaw != 0 || m_pendingPitch != 0) camera = orbit(camera, m_pendingYaw, m_pendingPitch), changed = true;
    if (m_pendingZoom != 1) camera = zoom(camera, m_pendingZoom), changed = true;
    m_pendingYaw = m_pendingPitch = 0, m_pendingZoom = 1;
    if (changed) setCamera(camera, "camera move");
}

bool Viewer::handleKey(const std::string& key)
{
    if (key == "H") std::fputs(viewerHelp(), stdout), std::fflush(stdout);
    else if (key == "R") m_context.device().waitIdle(), m_session->reset();
    else if (key == "P") m_paused = !m_paused;
    else if (key == "+" || key == "=") m_exposure += 0.5f;
    else if (key == "-") m_exposure -= 0.5f;
    else if (key == "F") m_filmic = !m_filmic;
    else if (key == "I") {
        m_context.device().waitIdle();
        bool path = scene().render.integrator == Integrator::Path;
        m_display.reset(); // it reads the old renderer's accumulation buffer
        m_session->setIntegrator(path ? Integrator::Whitted : Integrator::Path);
        createDisplay();
    } else if (key == "S") {
        ++m_saveCount;
        std::string stem = std::filesystem::path(scene().path).stem().string();
        save(stem + "-view-" + std::to_string(m_saveCount) + ".exr");
    } else {
        return false;
    }
    updateTitle(true);
    return true;
}

void Viewer::renderAndPresent(uint32_t frames)
{
    auto start = Clock::now();
    if (frames) m_session->renderFrames(frames);
    double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    m_rateSamples += uint64_t(frames) * renderer().width() * renderer().height();
    if (frames) m_pacer.record(frames, seconds);
    present();
    updateTitle();
}

void Viewer::present()
{
    if (m_swapchainStale) recreateSwapchain();
    if (m_context.device().waitForFences(*m_presented, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
        throw GpuError("vkWaitForFences failed while presenting");
    uint32_t index = 0;
    try {
        auto [result, acquired] = m_swapchain->raii().acquireNextImage(UINT64_MAX, *m_imageAvailable);
        index = acquired;
        if (result == vk::Result::eSuboptimalKHR) m_swapchainStale = true;
    } catch (const vk::OutOfDateKHRError&) {
        m_swapchainStale = true;
        return;
    }
    m_context.device().resetFences(*m_presented);
    vk::raii::CommandBuffer cmd = m_context.beginOneShot();
    gpu::DisplayConstants constants{std::exp2(m_exposure), renderer().width(), renderer().height(),
                                    m_filmic ? gpu::TONE_MAP_FILMIC : gpu::TONE_MAP_CLAMP};
    m_display->recordToneMap(*cmd, constants);
    m_display->recordBlit(*cmd, m_swapchain->image(index), m_swapchain->extent());
    cmd.end();
    vk::PipelineStageFlags waitStage = vk::PipelineStageFlagBits::eTransfer;
    vk::CommandBuffer handle = *cmd;
    vk::Semaphore wait = *m_imageAvailable, signal = *m_renderFinished;
    m_context.queue().submit(vk::SubmitInfo(wait, waitStage, handle, signal), *m_presented);
    vk::SwapchainKHR swapchain = m_swapchain->handle();
    try {
        if (m_context.queue().presentKHR(vk::PresentInfoKHR(signal, swapchain, index)) == vk::Result::eSuboptimalKHR)
            m_swapchainStale = true;
    } catch (const vk::OutOfDateKHRError&) {
        m_swapchainStale = true;
    }
    if (m_context.device().waitForFences(*m_presented, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
        throw GpuError("vkWaitForFences failed after presenting");
}

void Viewer::updateTitle(bool force)
{
    auto now = Clock::now();
    double since = std::chrono::duration<double>(now - m_rateStart).count();
    if (since >= 0.5) {
        m_samplesPerSecond = m_rateSamples / since;
        m_rateStart = now, m_rateSamples = 0;
    }
    if (!force && std::chrono::duration<double>(now - m_lastTitle).count() < 0.25) return;
    m_lastTitle = now;
    std::string error;
    if (m_options.variance && renderer().completedFrames() >= 2) {
        char text[64];
        std::snprintf(text, sizeof text, "  rel.MSE %.3g", m_session->film().estimated->relMse);
        error = text;
    }
    char title[512];
    std::snprintf(title, sizeof title, "vkrt view - %s - %s - %u spp - %ssamples/s%s - %s%s",
                  std::filesystem::path(scene().path).filename().c_str(),
                  integratorName(scene().render.integrator).c_str(), renderer().completedFrames(),
                  humanCount(m_samplesPerSecond).c_str(), error.c_str(), m_context.deviceInfo().name.c_str(),
                  m_paused ? " [paused]" : "");
    glfwSetWindowTitle(m_window.get(), title);
}

void Viewer::save(const std::string& exrPath)
{
    std::filesystem::path png = std::filesystem::path(exrPath).replace_extension(".png");
    // The scene may have changed since the start (a file dropped on the window): checked again here.
    refuseOverlappingFiles(inputsOf(scene()), {{"the saved EXR", exrPath}, {"the saved PNG", png}});
    m_context.device().waitIdle();
    Film film = m_session->film();
    std::map<std::string, Image> layers;
    if (film.variance) layers["variance"] = *film.variance;
    writeExr(exrPath, film.mean, m_session->metadata(film, "vkrt view"), layers);
    screenshot(png.string());
    std::printf("saved %s (%u spp) and %s\n", exrPath.c_str(), renderer().completedFrames(), png.c_str());
    std::fflush(stdout);
}

void Viewer::screenshot(const std::string& pngPath)
{
    refuseOverlappingFiles(inputsOf(scene()), {{"the screenshot", pngPath}});
    m_context.device().waitIdle();
    writePngPixels(pngPath, renderer().width(), renderer().height(), m_display->readPixels());
}

void Viewer::screenshotAndSay(const std::string& pngPath)
{
    present();
    screenshot(pngPath);
    std::printf("saved %s (%u spp)\n", pngPath.c_str(), renderer().completedFrames());
    std::fflush(stdout);
}

void Viewer::runScript(const std::vector<ViewerCommand>& commands)
{
    for (const ViewerCommand& c : commands) {
        if (c.name == "frames") {
            for (uint32_t left = uint32_t(c.numbers[0]); left > 0;) {
                uint32_t n = std::min(left, m_pacer.nextFrames());
                renderAndPresent(n);
                left -= n;
                glfwPollEvents();
            }
        } else if (c.name == "orbit") setCamera(orbit(scene().camera, c.numbers[0], c.numbers[1]), "orbit");
        else if (c.name == "fly") setCamera(fly(scene().camera, c.numbers[0], c.numbers[1], c.numbers[2]), "fly");
        else if (c.name == "zoom") setCamera(zoom(scene().camera, c.numbers[0]), "zoom");
        else if (c.name == "focus") focusAt(c.numbers[0], c.numbers[1]);
        else if (c.name == "open") openScene(c.text);
        else if (c.name == "exposure") m_exposure = float(c.numbers[0]);
        else if (c.name == "key") handleKey(c.text);
        else if (c.name == "save") save(c.text);
        else if (c.name == "screenshot") screenshotAndSay(c.text);
    }
}

void Viewer::runInteractive()
{
    std::fputs(viewerHelp(), stdout);
    auto last = Clock::now();
    while (!glfwWindowShouldClose(m_window.get())) {
        glfwPollEvents();
        if (glfwGetKey(m_window.get(), GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
        auto now = Clock::now();
        applyCameraInput(std::chrono::duration<double>(now - last).count());
        last = now;
        if (m_pendingFocus) focusAt(m_pendingFocus->first, m_pendingFocus->second), m_pendingFocus.reset();
        if (m_pendingOpen) openScene(*m_pendingOpen), m_pendingOpen.reset();
        while (!m_keys.empty()) {
            std::string key = m_keys.front();
            m_keys.pop_front();
            try {
                if (!flying()) handleKey(key);
            } catch (const InputError& e) { // S over one of the scene's files: say so, keep the session
                std::fprintf(stderr, "vkrt view: %s\n", e.what());
            }
        }
        renderAndPresent(m_paused ? 0 : m_pacer.nextFrames());
        if (m_paused) glfwWaitEventsTimeout(0.05);
    }
}

void Viewer::run(const std::vector<ViewerCommand>& script)
{
    if (script.empty()) runInteractive();
    else runScript(script);
}

/// The scripted part of a session: --script, or --frames [--screenshot].
std::vector<ViewerCommand> scriptFor(const ViewOptions& options)
{
    if (!options.script.empty()) return readViewerScript(options.script);
    std::vector<ViewerCommand> commands;
    // --screenshot alone renders this many frames first.
    constexpr uint32_t kScreenshotFrames = 64;
    if (options.frames || !options.screenshot.empty()) {
        commands.push_back({"frames", {double(options.frames.value_or(kScreenshotFrames))}, "", 0});
        if (!options.screenshot.empty()) commands.push_back({"screenshot", {}, options.screenshot, 0});
    }
    return commands;
}

/// The files a script writes: each `save` (its EXR and the PNG beside it) and `screenshot`.
std::vector<NamedFile> scriptOutputs(const std::vector<ViewerCommand>& script)
{
    std::vector<NamedFile> outputs;
    for (const ViewerCommand& c : script) {
        if (c.name == "save") {
            outputs.push_back({"a saved EXR", c.text});
            outputs.push_back({"a saved PNG", std::filesystem::path(c.text).replace_extension(".png")});
        }
        if (c.name == "screenshot") outputs.push_back({"a screenshot", c.text});
    }
    return outputs;
}

Outcome runViewer(const ViewOptions& options)
{
    std::vector<ViewerCommand> script = scriptFor(options); // mistakes surface before any window opens
    Viewer viewer(options, scriptOutputs(script));
    viewer.run(script);
    return withValidation(Outcome::passed(), viewer.validationMessages());
}

} // namespace vkrt
