#pragma once
// `vkrt regress`: renders every case of a suite, tests it against its
// reference, and writes a Markdown report, failure images and JUnit XML.
#include "gpu/ShaderCompiler.h"
#include "render/Outcome.h"
#include "render/RenderSession.h"

#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

struct RegressOptions {
    std::filesystem::path suite;
    std::vector<std::string> filters; ///< run cases whose name contains any of these (all when empty)
    std::string driver;               ///< Vulkan ICD manifest (JSON) to load instead of the system's
    std::string device;
    std::filesystem::path junit;     ///< JUnit XML output (optional)
    std::filesystem::path reportDir; ///< report.md and failure images
    bool update = false;             ///< regenerate the vkrt-made references
    uint32_t seedOffset = 0;         ///< added to the suite's seed (repeat runs)
    bool failOnSlowdown = false;
    AccelChoice accel = AccelChoice::Auto; ///< --accel: the traversal backend of every case
    std::vector<Define> kernelDefines; ///< test hooks: build every kernel with these
};

/// Runs the suite: Passed when every case passes, Failed when a case fails its
/// test, DeviceFailure (or BadInput) when a case could not render,
/// Interrupted on Ctrl-C (the finished cases are reported). Bad input
/// (manifest, references, options) throws InputError before anything renders.
Outcome runRegression(const RegressOptions& options);

/// Points the Vulkan loader at one ICD manifest; throws InputError naming the
/// path if it is missing, not a JSON ICD manifest, or names a library file
/// that does not exist. Call before any instance exists.
/// Creates --report-dir (and its parents); InputError naming the option if it cannot.
void createReportDir(const std::filesystem::path& dir);

void selectVulkanDriver(const std::filesystem::path& icdManifest);

} // namespace vkrt
