#pragma once
// Shared helpers for vkrt's tests: one Vulkan context per test process (with
// validation on, so every GPU test also fails on any validation message),
// scenes from text, and running the vkrt executable.
#include "gpu/VulkanContext.h"
#include "io/Image.h"
#include "render/Renderer.h"
#include "scene/Scene.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace vkrt::test {

/// The device tests run on: $VKRT_TEST_DEVICE (default: vkrt's own choice).
/// Validation is on whenever the Khronos layer is installed.
const VulkanContext& gpu();

/// Base for tests that use the GPU: fails the test if the validation layer
/// reported anything while it ran.
class GpuTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;

private:
    size_t m_messagesBefore = 0;
};

/// A fresh, empty directory removed at process exit is not guaranteed: tests use unique names.
std::filesystem::path freshTempDir(const std::string& name);

/// scenes/default.toml of the source tree: the scene `vkrt render` renders by default.
inline const std::string kDefaultScene = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/default.toml";

/// SPIR-V cache directory private to this test process.
std::filesystem::path testCacheDir();

/// Render options that sample pixel centres only (no jitter), with the test
/// cache: deterministic geometry for analytic and exact comparisons.
RenderOptions pixelCentreOptions();

/// Render options for statistical tests: jittered samples, a per-pixel
/// variance estimate (independent samples), `seed`, the test cache.
RenderOptions statisticalOptions(uint32_t seed);

/// Parses scene text (path used for messages and relative files).
Scene sceneFromText(const std::string& text, const std::string& path = "test.toml");

struct ProcessResult {
    int exitCode = -1;              ///< exit status, or 128 + signal
    std::string output;             ///< stdout and stderr interleaved
    int64_t peakResidentBytes = -1; ///< the process's largest resident set (runVkrt only; -1: unknown)
};

/// The most memory a test's vkrt process may use on bad input (issue 26:
/// no process of the suite needs more than 2 GB for any bad input).
constexpr int64_t kBadInputMemoryLimit = int64_t(2) << 30;

/// Runs the vkrt executable with `args` (each passed as one argument), with
/// stdin from /dev/null unless `stdinFile` names another file; measures its
/// peak resident memory (wait4's ru_maxrss).
ProcessResult runVkrt(const std::vector<std::string>& args, const std::string& stdinFile = "/dev/null");

/// Runs a shell command line as given (stdout and stderr captured together).
ProcessResult runShell(const std::string& command);

/// Single-quotes a string for the shell.
std::string shellQuote(const std::string& arg);

/// The message of the InputError `f` throws, or "" when it throws none.
std::string inputErrorOf(const std::function<void()>& f);

/// Writes text to a file (creating parent directories).
void writeText(const std::filesystem::path& path, const std::string& text);

/// The pooled z of one channel of every pixel of `mean` against the constant
/// `expected`: the summed differences over the root of the summed variances
/// of the means.
double pooledZ(const Image& mean, const Image& variance, int channel, double expected);

/// Mean of one channel over all pixels.
double channelMean(const Image& image, int channel);

/// Records a measured figure as a test property and prints it as "[   STAT   ] name = value".
void reportStat(const std::string& name, double value);

/// lib/pcg.glsl's pcg4d on the CPU, line by line.
std::array<uint32_t, 4> pcg4dReference(std::array<uint32_t, 4> v);

} // namespace vkrt::test
