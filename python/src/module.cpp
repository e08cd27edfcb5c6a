// vkrt._vkrt: the C++ side of the Python module (docs/python.md). Every
// render goes through the same RenderSession and the same EXR writer as the
// command line (render/RenderSession.h, render/RenderOutput.h); this file
// only converts arguments and results. The Python package (vkrt/__init__.py)
// adds the progressive generator and the documentation.
#include "gpu/VulkanContext.h"
#include "io/ExrFile.h"
#include "io/OutputPaths.h"
#include "render/ErrorMetrics.h"
#include "render/GpuScene.h"
#include "render/KernelVariant.h"
#include "render/RenderOutput.h"
#include "render/RenderSession.h"
#include "scene/FeatureSet.h"
#include "scene/MaterialUse.h"
#include "scene/SceneInputs.h"
#include "scene/SceneOverrides.h"
#include "scene/SceneParser.h"
#include "util/Error.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;

namespace vkrt {
namespace {

// ---------------------------------------------------------------- errors

/// vkrt.SceneError and vkrt.VkrtError, created at import (PYBIND11_MODULE).
PyObject* g_sceneError = nullptr;
PyObject* g_vkrtError = nullptr;

/// Raises vkrt.SceneError(text) with file, line, column and message attributes.
[[noreturn]] void raiseSceneError(const std::string& file, int line, int column, const std::string& message,
                                  const std::string& text)
{
    py::gil_scoped_acquire acquire;
    py::object type = py::reinterpret_borrow<py::object>(g_sceneError);
    py::object exception = type(py::str(text));
    exception.attr("file") = file;
    exception.attr("line") = line > 0 ? py::object(py::int_(line)) : py::none();
    exception.attr("column") = column > 0 ? py::object(py::int_(column)) : py::none();
    exception.attr("message") = message;
    PyErr_SetObject(g_sceneError, exception.ptr());
    throw py::error_already_set();
}

[[noreturn]] void raiseSceneError(const SceneError& error)
{
    raiseSceneError(error.where().file, error.where().line, error.where().column, error.message(), error.what());
}

// ---------------------------------------------------------------- scenes

/// A parsed, validated scene. Python's Scene wraps one; changes from
/// Python (camera, materials) are checked with the parser's own rules.
struct PyScene {
    Scene scene;
    std::string source; ///< the file, or "<base_dir>/<string>" for text
};

PyScene loadSceneFile(const std::filesystem::path& path)
{
    try {
        py::gil_scoped_release release;
        return PyScene{loadScene(path.string()), path.string()};
    } catch (const SceneError& error) {
        raiseSceneError(error);
    } catch (const InputError& error) {
        // A file that cannot be read (or a mesh it names): no line or column to give.
        raiseSceneError(path.string(), 0, 0, error.what(), error.what());
    }
}

PyScene sceneFromToml(const std::string& text, const std::filesystem::path& baseDir)
{
    try {
        // The name resolves the scene's relative paths against base_dir and names the text in messages.
        const std::string name = (baseDir / "<string>").string();
        Scene scene = parseSceneString(text, name);
        for (const std::string& warning : scene.warnings) std::fprintf(stderr, "vkrt: warning: %s\n", warning.c_str());
        return PyScene{std::move(scene), name};
    } catch (const SceneError& error) {
        raiseSceneError(error);
    }
}

py::dict sceneInfo(const PyScene& s)
{
    const Scene& scene = s.scene;
    KernelVariant variant(featuresOf(scene));
    variant.uniformScene = sceneFitsUniformBuffers(scene);
    py::dict defines;
    for (const auto& [name, value] : variant.defines()) defines[py::str(name)] = value;
    py::dict info;
    info["source"] = s.source;
    info["integrator"] = integratorName(scene.render.integrator);
    info["kernel"] = variant.describe();
    info["defines"] = defines;
    info["width"] = scene.camera.width;
    info["height"] = scene.camera.height;
    py::dict shapes, lights;
    for (size_t k = 0; k < kShapeKindCount; ++k)
        if (scene.count(ShapeKind(k)) > 0) shapes[py::str(featureName(ShapeKind(k)))] = scene.count(ShapeKind(k));
    for (size_t k = 0; k < kLightKindCount; ++k)
        if (scene.count(LightKind(k)) > 0) lights[py::str(featureName(LightKind(k)))] = scene.count(LightKind(k));
    info["shapes"] = shapes;
    info["lights"] = lights;
    info["triangles"] = meshTriangleCount(scene);
    info["emissive_triangles"] = emissiveTriangleCount(scene);
    info["materials"] = scene.materials.size();
    return info;
}

using Vec3 = std::array<double, 3>;

glm::dvec3 toVec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 fromVec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

/// Moves the camera; the scene is unchanged when the parser would refuse the result.
void setCamera(PyScene& s, std::optional<Vec3> eye, std::optional<Vec3> target, std::optional<Vec3> up,
               std::optional<double> fov, std::optional<double> aperture, std::optional<double> focusDistance)
{
    Camera camera = s.scene.camera;
    if (eye) camera.eye = toVec(*eye);
    if (target) camera.target = toVec(*target);
    if (up) camera.up = toVec(*up);
    if (fov) camera.fovY = *fov;
    if (aperture) camera.apertureRadius = *aperture;
    if (focusDistance) camera.focusDistance = *focusDistance;
    if (const std::optional<std::string> problem = cameraProblem(camera)) throw py::value_error("camera: " + *problem);
    s.scene.camera = camera;
}

/// Replaces material `name` by the one `table` (TOML: the keys of a
/// `[materials.NAME]` table) describes, read by the scene parser.
void setMaterial(PyScene& s, const std::string& name, const std::string& table)
{
    auto it = std::find_if(s.scene.materials.begin(), s.scene.materials.end(),
                           [&](const Material& m) { return m.name == name; });
    if (it == s.scene.materials.end()) {
        std::string names;
        for (const Material& m : s.scene.materials) names += (names.empty() ? "" : ", ") + m.name;
        throw py::key_error("no material \"" + name + "\" in " + s.source + " (it has: " + names + ")");
    }
    try {
        Material material =
            parseMaterialTable(table, "<material " + name + ">", name, std::filesystem::path(s.source).parent_path());
        // Where the scene uses it, as the parser checks each object (an
        // emissive material on a sphere was accepted and its emission ignored).
        std::swap(*it, material);
        if (auto problem = materialUseProblem(s.scene, uint32_t(it - s.scene.materials.begin()))) {
            std::swap(*it, material);
            throw py::value_error("set_material(\"" + name + "\"): " + *problem);
        }
    } catch (const SceneError& error) {
        raiseSceneError(error);
    }
}

py::list materialNames(const PyScene& s)
{
    py::list names;
    for (const Material& m : s.scene.materials) names.append(m.name);
    return names;
}

py::dict cameraOf(const PyScene& s)
{
    const Camera& c = s.scene.camera;
    py::dict d;
    d["eye"] = fromVec(c.eye);
    d["target"] = fromVec(c.target);
    d["up"] = fromVec(c.up);
    d["fov"] = c.fovY;
    d["aperture"] = c.apertureRadius;
    d["focus_distance"] = c.resolvedFocusDistance();
    d["width"] = c.width;
    d["height"] = c.height;
    return d;
}

// ---------------------------------------------------------------- devices

/// One Vulkan context per device selector, made on first use and kept for
/// the life of the process (an instance and device take a while to make).
/// A device renders one session at a time: a second thread waits for it.
struct Device {
    std::unique_ptr<VulkanContext> context;
    std::mutex busy;
};

std::mutex g_devicesMutex;
std::map<std::string, std::shared_ptr<Device>>& openDevices()
{
    static std::map<std::string, std::shared_ptr<Device>> devices;
    return devices;
}

/// The device for `selector` (called without the GIL). Sessions hold it, so
/// it outlives the map's entry (cleared at exit) while one is alive.
std::shared_ptr<Device> deviceFor(const std::string& selector)
{
    std::lock_guard lock(g_devicesMutex);
    auto& devices = openDevices();
    auto it = devices.find(selector);
    if (it != devices.end()) return it->second;
    auto device = std::make_shared<Device>();
    device->context = std::make_unique<VulkanContext>(ContextOptions{selector, false, std::nullopt});
    return devices.emplace(selector, std::move(device)).first->second;
}

py::list listVulkanDevicesForPython()
{
    std::vector<DeviceInfo> devices;
    {
        py::gil_scoped_release release;
        tuneSoftwareRasterizerThreads();
        devices = listVulkanDevices();
    }
    std::optional<uint32_t> chosen;
    try {
        chosen = defaultDeviceIndex(devices);
    } catch (const GpuError&) {
    }
    py::list out;
    for (const DeviceInfo& d : devices) {
        py::dict entry;
        entry["index"] = d.index;
        entry["name"] = d.name;
        entry["type"] = d.typeName();
        entry["api"] = d.apiVersionString();
        entry["driver"] = d.driver;
        entry["default"] = chosen == d.index;
        entry["suitable"] = d.suitable();
        entry["unsuitable_reason"] = d.unsuitableReason;
        entry["ray_query"] = d.rayQuery();
        out.append(entry);
    }
    return out;
}

// ---------------------------------------------------------------- results

/// A float32 array of shape (height, width, channels), or (height, width)
/// for one channel, over `data`, which `owner` keeps alive: no copy.
py::array_t<float> imageArray(const float* data, uint32_t width, uint32_t height, uint32_t channels, py::capsule owner)
{
    const py::ssize_t w = width, h = height, c = channels, f = sizeof(float);
    if (channels == 1) return py::array_t<float>({h, w}, {w * f, f}, data, owner);
    return py::array_t<float>({h, w, c}, {w * c * f, c * f, f}, data, owner);
}

/// The same over `values`, moved into the array's keeping.
py::array_t<float> imageArray(std::vector<float>&& values, uint32_t width, uint32_t height, uint32_t channels)
{
    auto* owned = new std::vector<float>(std::move(values));
    py::capsule free(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return imageArray(owned->data(), width, height, channels, free);
}

py::object metadataValue(const MetadataValue& value)
{
    return std::visit([](const auto& v) -> py::object { return py::cast(v); }, value);
}

/// What render() and a session's snapshot return: the EXR's contents, with
/// NumPy views for Python, and the means to write it as `vkrt render` does.
struct PyResult {
    std::shared_ptr<const RenderOutput> output;
    py::dict arrays; ///< "image", "variance", "albedo", "normal", "position", "depth"
    py::dict metadata;
    uint32_t spp = 0;
    double renderSeconds = 0.0;
    std::string stoppedBy;
    bool interrupted = false;
    py::object errorEstimate = py::none(); ///< {"rmse", "rel_mse"} from the kernel's variance, or None
    std::vector<NamedFile> inputs;         ///< the scene file and every file it read, which save() must not overwrite

    /// The command line's rule (io/OutputPaths.h): the output may not be the
    /// scene file or any file it read, and must be a place vkrt can write.
    /// The format comes from the extension (.exr or .png), as `vkrt render -o`'s.
    void save(const std::filesystem::path& path, float exposure, bool filmic) const
    {
        py::gil_scoped_release release;
        checkOutputs(inputs, {{"save()'s path", path}});
        writeRenderImage(path, *output, PngLook{exposure, filmic ? ToneCurve::Filmic : ToneCurve::Clamp},
                         "save()'s path");
    }
};

/// Converts a finished session's output. The arrays are read-only views of
/// the pixels save() writes (no copy): each holds a reference to them.
std::unique_ptr<PyResult> resultOf(RenderOutput rendered, const std::optional<EstimatedError>& estimated,
                                   const RenderSession& session)
{
    auto result = std::make_unique<PyResult>();
    if (estimated) {
        py::dict error;
        error["rmse"] = estimated->rmse;
        error["rel_mse"] = estimated->relMse;
        error["rel_mse_upper"] = estimated->relMseUpper;
        result->errorEstimate = error;
    }
    auto shared = std::make_shared<const RenderOutput>(std::move(rendered));
    result->output = shared;
    const RenderOutput& output = *shared;
    const auto view = [&](const std::vector<float>& values, uint32_t channels) {
        auto* keep = new std::shared_ptr<const RenderOutput>(shared);
        py::capsule owner(keep, [](void* p) { delete static_cast<std::shared_ptr<const RenderOutput>*>(p); });
        py::array_t<float> array = imageArray(values.data(), output.mean.width, output.mean.height, channels, owner);
        // Read-only: save() writes these very pixels, so a change would leak into the file.
        py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
        return array;
    };
    result->arrays["image"] = view(output.mean.rgb, 3);
    for (const auto& [name, layer] : output.layers) result->arrays[py::str(name)] = view(layer.rgb, 3);
    for (size_t k = 0; k < output.channels.size(); ++k)
        result->arrays[py::str(output.channelAovs[k])] =
            view(output.channels[k].values, uint32_t(output.channels[k].names.size()));
    for (const auto& [key, value] : output.metadata) result->metadata[py::str(key)] = metadataValue(value);
    result->spp = session.spp();
    result->inputs = filesTheSceneRead(session.scene());
    result->inputs.push_back({"the scene file", session.scene().path});
    result->renderSeconds = session.renderSeconds();
    if (session.stoppedBy()) result->stoppedBy = stopReasonName(*session.stoppedBy());
    result->interrupted = session.outcome().kind == OutcomeKind::Interrupted;
    return result;
}

// ---------------------------------------------------------------- sessions

struct RenderArguments {
    std::optional<uint32_t> spp, width, height;
    uint32_t seed = 0;
    std::string sampler = "auto";
    std::optional<std::string> integrator;
    std::string device;
    std::optional<double> timeBudget, targetError;
    bool variance = false;
    std::vector<std::string> aovs;
    std::string accel = "auto";
};

Integrator integratorNamed(const std::string& name)
{
    if (name == "path") return Integrator::Path;
    if (name == "whitted") return Integrator::Whitted;
    throw py::value_error("integrator: expected \"path\" or \"whitted\", got \"" + name + "\"");
}

/// The scene as the arguments change it (a copy: the Python Scene stays as it was).
Scene sceneFor(const PyScene& s, const RenderArguments& a)
{
    Scene scene = s.scene;
    applyResolution(scene.camera, ResolutionOverride{a.width, a.height, "width", "height"});
    if (a.integrator) scene.render.integrator = integratorNamed(*a.integrator);
    return scene;
}

/// The command line's sessionConfig (app/RenderCommand.cpp) for the same choices.
SessionConfig configFor(const RenderArguments& a, const std::atomic<bool>* interrupt)
{
    SessionConfig config;
    config.seed = a.seed;
    const std::optional<SamplerChoice> sampler = samplerChoiceNamed(a.sampler);
    if (!sampler)
        throw py::value_error("sampler: expected \"auto\", \"independent\" or \"sobol\", got \"" + a.sampler + "\"");
    config.sampler = *sampler;
    const std::optional<AccelChoice> accel = accelChoiceNamed(a.accel);
    if (!accel) throw py::value_error("accel: expected \"auto\", \"own\" or \"driver\", got \"" + a.accel + "\"");
    config.accel = *accel;
    if (a.spp && *a.spp == 0) throw py::value_error("spp: must be at least 1");
    if (a.timeBudget && !(*a.timeBudget > 0.0 && std::isfinite(*a.timeBudget)))
        throw py::value_error("time_budget: must be > 0 seconds and finite");
    if (a.targetError && !(*a.targetError > 0.0 && std::isfinite(*a.targetError)))
        throw py::value_error("target_error: must be > 0 and finite");
    config.variance = {a.variance, a.targetError.has_value()};
    config.aov = !a.aovs.empty();
    config.stop = {sppCap(a.spp, a.timeBudget || a.targetError), a.timeBudget, a.targetError, interrupt};
    return config;
}

/// A render session on one device, kept between calls: the progressive
/// generator renders batches into it, and run() renders to its stop rules.
class PySession {
public:
    PySession(const PyScene& scene, RenderArguments arguments) : m_arguments(std::move(arguments))
    {
        m_aovs = checkedAovNames(m_arguments.aovs, "aovs");
        Scene copy = sceneFor(scene, m_arguments);
        SessionConfig config = configFor(m_arguments, &m_interrupt);
        py::gil_scoped_release release;
        m_device = deviceFor(m_arguments.device);
        std::lock_guard lock(m_device->busy);
        m_session = std::make_unique<RenderSession>(*m_device->context, std::move(copy), std::move(config));
    }

    /// Renders to the stop rules; Ctrl-C (checked between submissions) stops it with the image so far.
    void run()
    {
        withSignals([this](const RunHooks& hooks) { m_session->run(hooks); });
    }

    /// Renders `frames` more samples per pixel (outside the stop rules but
    /// Ctrl-C); KeyboardInterrupt leaves the frames done so far in the film.
    void runFrames(uint32_t frames)
    {
        withSignals([this, frames](const RunHooks& hooks) { m_session->runFrames(frames, hooks); });
    }

    std::unique_ptr<PyResult> result() const
    {
        RenderOutput output;
        std::optional<EstimatedError> estimated;
        {
            py::gil_scoped_release release;
            std::lock_guard lock(m_device->busy);
            Film film = m_session->film();
            estimated = film.estimated;
            output = renderOutput(*m_session, std::move(film), m_arguments.variance, m_aovs);
        }
        return resultOf(std::move(output), estimated, *m_session);
    }

    uint32_t spp() const { return m_session->spp(); }

    /// Asks a running loop to stop after its current submission (from a signal handler).
    void interrupt() { m_interrupt = true; }

    /// The session's GPU objects go while no other session uses the device
    /// (another thread may be rendering on its queue).
    ~PySession()
    {
        py::gil_scoped_release release;
        std::lock_guard lock(m_device->busy);
        m_session.reset(); // before the device it was made on
    }
    PySession(const PySession&) = delete;
    PySession& operator=(const PySession&) = delete;

private:
    RenderArguments m_arguments;
    std::vector<std::string> m_aovs;
    std::shared_ptr<Device> m_device;
    std::unique_ptr<RenderSession> m_session;
    std::atomic<bool> m_interrupt{false};
    std::unique_ptr<py::error_already_set> m_pendingError;

    /// Runs `loop` on the device without the GIL. Python's signal handlers
    /// run between submissions: Ctrl-C sets the interrupt the render loop
    /// polls, and its KeyboardInterrupt is raised once the loop has stopped.
    template <class Loop>
    void withSignals(const Loop& loop)
    {
        m_interrupt = false;
        RunHooks hooks;
        hooks.onProgress = [this](uint32_t) {
            py::gil_scoped_acquire acquire;
            if (!m_pendingError && PyErr_CheckSignals() != 0) {
                m_interrupt = true;
                m_pendingError = std::make_unique<py::error_already_set>();
            }
        };
        {
            py::gil_scoped_release release;
            std::lock_guard lock(m_device->busy);
            loop(hooks);
        }
        if (!m_pendingError) return;
        std::unique_ptr<py::error_already_set> error = std::move(m_pendingError);
        error->restore();
        throw py::error_already_set();
    }
};

/// Runs `body`, turning vkrt's C++ errors into Python ones.
template <class Body>
auto translated(Body&& body) -> decltype(body())
{
    try {
        return body();
    } catch (const SceneError& error) {
        raiseSceneError(error);
    } catch (const InputError& error) {
        throw py::value_error(error.what());
    } catch (const GpuError& error) {
        PyErr_SetString(g_vkrtError, error.what());
        throw py::error_already_set();
    }
}

} // namespace
} // namespace vkrt

PYBIND11_MODULE(_vkrt, m)
{
    using namespace vkrt;
    m.doc() = "vkrt's C++ side; use the vkrt package (docs/python.md).";

    static py::exception<GpuError> vkrtError(m, "VkrtError", PyExc_RuntimeError);
    g_vkrtError = vkrtError.ptr();
    static py::exception<SceneError> sceneError(m, "SceneError", PyExc_ValueError);
    g_sceneError = sceneError.ptr();

    py::class_<PyScene>(m, "Scene")
        .def_static("load", &loadSceneFile, py::arg("path"))
        .def_static("from_toml", &sceneFromToml, py::arg("text"), py::arg("base_dir"))
        .def("info", &sceneInfo)
        .def("camera", &cameraOf)
        .def("set_camera", &setCamera, py::arg("eye") = py::none(), py::arg("target") = py::none(),
             py::arg("up") = py::none(), py::arg("fov") = py::none(), py::arg("aperture") = py::none(),
             py::arg("focus_distance") = py::none())
        .def("set_material", &setMaterial, py::arg("name"), py::arg("table"))
        .def("materials", &materialNames)
        .def("copy", [](const PyScene& s) { return PyScene(s); })
        .def_readonly("source", &PyScene::source);

    py::class_<PyResult>(m, "Result")
        .def_readonly("arrays", &PyResult::arrays)
        .def_readonly("metadata", &PyResult::metadata)
        .def_readonly("spp", &PyResult::spp)
        .def_readonly("render_seconds", &PyResult::renderSeconds)
        .def_readonly("stopped_by", &PyResult::stoppedBy)
        .def_readonly("interrupted", &PyResult::interrupted)
        .def_readonly("error_estimate", &PyResult::errorEstimate)
        .def(
            "save",
            [](const PyResult& r, const std::filesystem::path& path, float exposure, bool filmic) {
                translated([&] { r.save(path, exposure, filmic); });
            },
            py::arg("path"), py::arg("exposure"), py::arg("filmic"));

    py::class_<PySession>(m, "Session")
        .def(py::init([](const PyScene& scene, std::optional<uint32_t> spp, std::optional<uint32_t> width,
                         std::optional<uint32_t> height, uint32_t seed, std::string sampler,
                         std::optional<std::string> integrator, std::string device, std::optional<double> timeBudget,
                         std::optional<double> targetError, bool variance, std::vector<std::string> aovs,
                         std::string accel) {
                 return translated([&] {
                     return std::make_unique<PySession>(scene,
                                                        RenderArguments{spp, width, height, seed, std::move(sampler),
                                                                        std::move(integrator), std::move(device),
                                                                        timeBudget, targetError, variance,
                                                                        std::move(aovs), std::move(accel)});
                 });
             }),
             py::arg("scene"), py::arg("spp"), py::arg("width"), py::arg("height"), py::arg("seed"), py::arg("sampler"),
             py::arg("integrator"), py::arg("device"), py::arg("time_budget"), py::arg("target_error"),
             py::arg("variance"), py::arg("aovs"), py::arg("accel"))
        .def("run", [](PySession& s) { translated([&] { s.run(); }); })
        .def(
            "run_frames", [](PySession& s, uint32_t frames) { translated([&] { s.runFrames(frames); }); },
            py::arg("frames"))
        .def("result", [](const PySession& s) { return translated([&] { return s.result(); }); })
        .def("interrupt", &PySession::interrupt)
        .def_property_readonly("spp", &PySession::spp);

    m.def("devices", [] { return translated([] { return listVulkanDevicesForPython(); }); });

    // The devices' Vulkan contexts go before the interpreter does, not in
    // static destruction, after the driver's own threads may have stopped.
    py::module_::import("atexit").attr("register")(py::cpp_function([] {
        py::gil_scoped_release release;
        std::lock_guard lock(g_devicesMutex);
        openDevices().clear();
    }));

    m.def(
        "measure_error",
        [](py::array_t<float, py::array::c_style | py::array::forcecast> image,
           py::array_t<float, py::array::c_style | py::array::forcecast> reference) {
            const auto imageOf = [](const py::array_t<float, py::array::c_style | py::array::forcecast>& a,
                                    const char* what) {
                if (a.ndim() != 3 || a.shape(2) != 3)
                    throw py::value_error(std::string(what) + ": expected an array of shape (height, width, 3)");
                Image out(uint32_t(a.shape(1)), uint32_t(a.shape(0)));
                std::copy(a.data(), a.data() + a.size(), out.rgb.begin());
                return out;
            };
            const Image a = imageOf(image, "image"), b = imageOf(reference, "reference");
            if (a.width != b.width || a.height != b.height)
                throw py::value_error("image and reference: different shapes");
            const MeasuredError e = measureError(a, b);
            // No value finite in both (or an empty image): there is no error to report, and 0 would say "equal".
            if (e.compared == 0)
                throw py::value_error("image and reference: no value is finite in both (" +
                                      std::to_string(e.nonFiniteA) + " non-finite in the image, " +
                                      std::to_string(e.nonFiniteB) + " in the reference); nothing to compare");
            py::dict out;
            out["rmse"] = e.rmse;
            out["mse"] = e.rmse * e.rmse;
            out["rel_mse"] = e.relMse;
            out["mape"] = e.mape;
            out["max_abs"] = e.maxAbs;
            out["compared"] = e.compared;
            out["non_finite_image"] = e.nonFiniteA;
            out["non_finite_reference"] = e.nonFiniteB;
            return out;
        },
        py::arg("image"), py::arg("reference"));

    m.def(
        "read_exr",
        [](const std::filesystem::path& path) {
            return translated([&] {
                ExrContents contents;
                {
                    py::gil_scoped_release release;
                    contents = readExr(path);
                }
                const uint32_t w = contents.image.width, h = contents.image.height;
                py::dict arrays;
                arrays["image"] = imageArray(std::move(contents.image.rgb), w, h, 3);
                for (auto& [name, layer] : contents.layers)
                    arrays[py::str(name)] = imageArray(std::move(layer.rgb), w, h, 3);
                // Other channels by group; vkrt's AOV channels under the names render() gives them.
                const std::map<std::string, std::vector<std::string>> aovChannels{{"normal", {"N.X", "N.Y", "N.Z"}},
                                                                                  {"position", {"P.X", "P.Y", "P.Z"}},
                                                                                  {"depth", {"Z"}}};
                for (auto& [group, channels] : contents.channels) {
                    std::string key = group;
                    for (const auto& [aov, names] : aovChannels)
                        if (channels.names == names) key = aov;
                    if (arrays.contains(key)) key = group; // never hide a layer of the same name
                    const auto count = uint32_t(channels.names.size());
                    arrays[py::str(key)] = imageArray(std::move(channels.values), w, h, count);
                }
                py::dict metadata;
                for (const auto& [key, value] : contents.metadata) metadata[py::str(key)] = metadataValue(value);
                return py::make_tuple(arrays, metadata);
            });
        },
        py::arg("path"));
}
