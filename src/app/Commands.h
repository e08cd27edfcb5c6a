#pragma once
// Subcommands of the vkrt executable. Each registers its options on the CLI11
// app and returns the function that runs it (returning the exit code).
#include "gpu/ShaderCompiler.h"
#include "render/RenderSession.h"

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace vkrt {

using CommandRunner = std::function<int()>;

/// `vkrt --version`: the version, the git commit it was built from, and the
/// Vulkan device (and driver) a command would use by default, or why none.
std::string versionText();

CommandRunner addRenderCommand(CLI::App& app);
CommandRunner addDevicesCommand(CLI::App& app);
CommandRunner addInfoCommand(CLI::App& app);
CommandRunner addCompareCommand(CLI::App& app);
CommandRunner addMergeCommand(CLI::App& app);
CommandRunner addViewCommand(CLI::App& app);
CommandRunner addRegressCommand(CLI::App& app);

/// NAME=VALUE texts of --kernel-define (the kernels' test and measurement
/// hooks) as defines; InputError names a malformed one.
std::vector<Define> parseKernelDefines(const std::vector<std::string>& texts);

/// Adds `--accel own|driver|auto` (the traversal backend, render/RenderSession.h:
/// AccelChoice) to a command, writing the choice to `choice`.
void addAccelOption(CLI::App& command, AccelChoice& choice);
/// Adds --scene-reads (auto, address or descriptor: RenderOptions::sceneReads) to a command.
void addSceneReadsOption(CLI::App& command, SceneReads& reads);

/// Adds the hidden test hook `--max-texture-chunk-bytes N` (RenderOptions::
/// maxTextureChunkBytes: a scene's texels split into buffers of at most N
/// bytes) to a command, writing N to `bytes`.
void addTextureChunkOption(CLI::App& command, uint64_t& bytes);

/// Process exit codes.
enum ExitCode : int {
    kExitOk = 0,
    kExitFailure = 1,       ///< GPU, driver or internal failure
    kExitBadInput = 2,      ///< scene file, option or input image error
    kExitValidation = 3,    ///< Vulkan validation layer reported messages
    kExitCompareFailed = 4, ///< `compare`: a threshold or the pixel test failed
    kExitDriverCrashed = 5, ///< the Vulkan driver crashed (SIGSEGV, ...) inside vkrt's calls to it (util/Signals.h)
    kExitInterrupted = 130  ///< SIGINT; partial results were written
};

} // namespace vkrt
