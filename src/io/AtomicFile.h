#pragma once
// Output files appear whole or not at all: write to a temporary file beside the
// target, then rename it over the target (atomic within one file system).
#include <filesystem>
#include <functional>

namespace vkrt {

/// Calls write(temporaryPath) and renames the result to `path`. If `write`
/// throws, the temporary is removed and the exception propagates; an existing
/// file at `path` is left untouched. Throws InputError naming `path` on failure.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path&)>& write);

} // namespace vkrt
