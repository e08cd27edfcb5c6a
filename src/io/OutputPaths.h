#pragma once
// Checks a command makes on its output paths before any work: an output must
// not be one of the command's inputs or another of its outputs (same path, or
// the same file through a link), and must be a place vkrt can write
// (io/AtomicFile.h), so that a long render never ends by destroying its own
// scene or failing to save.
#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

/// A file a command reads or writes, with what named it ("-o", "--png",
/// "the scene file", "shard") for messages.
struct NamedFile {
    std::string role;
    std::filesystem::path path;
};

/// Throws InputError, naming the output's path and both roles, if an output is
/// the same file as an input or as an earlier output. Empty paths are skipped;
/// outputs that are /dev/null may repeat.
void refuseOverlappingFiles(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

/// refuseOverlappingFiles, then each output must resolve to a regular file or
/// /dev/null in an existing directory that vkrt may write in.
void checkOutputs(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

} // namespace vkrt
