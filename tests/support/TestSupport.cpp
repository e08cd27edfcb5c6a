#include "support/TestSupport.h"

#include "scene/SceneParser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <cerrno>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt::test {

namespace {

bool validationLayerInstalled()
{
    vk::raii::Context context;
    for (const auto& layer : context.enumerateInstanceLayerProperties())
        if (std::string(layer.layerName.data()) == "VK_LAYER_KHRONOS_validation") return true;
    return false;
}

} // namespace

std::string shellQuote(const std::string& arg)
{
    std::string quoted = "'";
    for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

const VulkanContext& gpu()
{
    static std::unique_ptr<VulkanContext> context = [] {
        const char* device = std::getenv("VKRT_TEST_DEVICE");
        return std::make_unique<VulkanContext>(ContextOptions{device ? device : "", validationLayerInstalled()});
    }();
    return *context;
}

void GpuTest::SetUp() { m_messagesBefore = gpu().validationMessages().size(); }

void GpuTest::TearDown()
{
    auto messages = gpu().validationMessages();
    for (size_t i = m_messagesBefore; i < messages.size(); ++i) ADD_FAILURE() << messages[i];
}

fs::path freshTempDir(const std::string& name)
{
    fs::path dir = fs::temp_directory_path() / ("vkrt-test-" + std::to_string(getpid()) + "-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

fs::path testCacheDir()
{
    static fs::path dir = freshTempDir("spirv-cache");
    return dir;
}

namespace {

// Tests never fill the user's texture cache (texture/TextureCache.h): theirs
// is a fresh folder per test process, inherited by the vkrt processes they
// start; a test that wants another sets its own and restores this one.
const bool kTestsHaveTheirOwnTextureCache = [] {
    if (!std::getenv("VKRT_TEXTURE_CACHE_DIR"))
        setenv("VKRT_TEXTURE_CACHE_DIR", freshTempDir("texture-cache").c_str(), 1);
    return true;
}();

} // namespace

RenderOptions pixelCentreOptions()
{
    RenderOptions options;
    options.jitter = false;
    options.cacheDirectory = testCacheDir();
    return options;
}

RenderOptions statisticalOptions(uint32_t seed)
{
    RenderOptions options = pixelCentreOptions();
    options.jitter = true;
    options.variance = true;
    options.seed = seed;
    return options;
}

Scene sceneFromText(const std::string& text, const std::string& path) { return parseSceneString(text, path); }

ProcessResult runVkrt(const std::vector<std::string>& args, const std::string& stdinFile)
{
    int output[2];
    if (pipe(output) != 0) return {};
    const pid_t child = fork();
    if (child < 0) return {};
    if (child == 0) {
        // The vkrt process itself (no shell between), so wait4 sees its memory.
        const int input = open(stdinFile.c_str(), O_RDONLY);
        if (input >= 0) dup2(input, STDIN_FILENO);
        dup2(output[1], STDOUT_FILENO);
        dup2(output[1], STDERR_FILENO);
        close(output[0]);
        std::vector<char*> argv{const_cast<char*>(VKRT_BINARY)};
        for (const auto& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
        argv.push_back(nullptr);
        execv(VKRT_BINARY, argv.data());
        _exit(127);
    }
    close(output[1]);
    ProcessResult result;
    char buffer[4096];
    ssize_t n;
    while ((n = read(output[0], buffer, sizeof buffer)) > 0 || (n < 0 && errno == EINTR))
        if (n > 0) result.output.append(buffer, static_cast<size_t>(n));
    close(output[0]);
    int status = 0;
    rusage usage{};
    while (wait4(child, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    result.peakResidentBytes = static_cast<int64_t>(usage.ru_maxrss) * 1024; // Linux reports KiB
    return result;
}

ProcessResult runShell(const std::string& shellCommand)
{
    std::string command = shellCommand + " 2>&1";
    ProcessResult result;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return result;
    char buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
    int status = pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return result;
}

void writeText(const fs::path& path, const std::string& text)
{
    if (path.has_parent_path()) fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
}

void reportStat(const std::string& name, double value)
{
    std::ostringstream text;
    text << std::setprecision(6) << value;
    ::testing::Test::RecordProperty(name, text.str());
    std::cout << "[   STAT   ] " << name << " = " << text.str() << std::endl;
}

std::array<uint32_t, 4> pcg4dReference(std::array<uint32_t, 4> v)
{
    for (uint32_t& x : v) x = x * 1664525u + 1013904223u;
    v[0] += v[1] * v[3];
    v[1] += v[2] * v[0];
    v[2] += v[0] * v[1];
    v[3] += v[1] * v[2];
    for (uint32_t& x : v) x ^= x >> 16u;
    v[0] += v[1] * v[3];
    v[1] += v[2] * v[0];
    v[2] += v[0] * v[1];
    v[3] += v[1] * v[2];
    return v;
}

double pooledZ(const Image& mean, const Image& variance, int channel, double expected)
{
    double difference = 0.0, var = 0.0;
    for (size_t i = 0; i < mean.pixelCount(); ++i) {
        difference += mean.rgb[i * 3 + channel] - expected;
        var += variance.rgb[i * 3 + channel];
    }
    return difference / std::sqrt(var);
}

double channelMean(const Image& image, int channel)
{
    double sum = 0.0;
    for (size_t i = 0; i < image.pixelCount(); ++i) sum += image.rgb[i * 3 + channel];
    return sum / double(image.pixelCount());
}

std::string inputErrorOf(const std::function<void()>& f)
{
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

} // namespace vkrt::test
