#pragma once
// `vkrt regress`: renders every case of a suite, tests it against its
// reference, and writes a Markdown report, failure images and JUnit XML.
#include "gpu/ShaderCompiler.h"

#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

struct RegressOptions {
    std::filesystem::path suite;
    std::string filter;                ///< run cases whose name contains this
    std::string driver;                ///< Vulkan ICD manifest (JSON) to load instead of the system's
    std::string device;
    std::filesystem::path junit;       ///< JUnit XML output (optional)
    std::filesystem::path reportDir;   ///< report.md and failure images
    bool update = false;               ///< regenerate the vkrt-made references
    uint32_t seedOffset = 0;           ///< added to the suite's seed (repeat runs)
    bool failOnSlowdown = false;
    std::vector<Define> kernelDefines; ///< test hooks: build every kernel with these
};

/// Runs the suite; returns the exit code (0 only when every case passes).
int runRegression(const RegressOptions& options);

/// Points the Vulkan loader at one ICD manifest; throws InputError naming the
/// path if it is missing or not a JSON ICD manifest. Call before any instance exists.
void selectVulkanDriver(const std::filesystem::path& icdManifest);

} // namespace vkrt
