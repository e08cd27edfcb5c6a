#pragma once
// A check of a PLY file's header before the Open Asset Import Library reads
// it. Assimp 5.2 trusts the header: a header without `end_header`, with a
// property of an unknown type, or with element counts the file cannot hold
// makes it loop for minutes, allocating (tools/fuzz.sh found such files).
// This check refuses them in one pass over the header, with the line.
#include <filesystem>

namespace vkrt {

/// Throws InputError ("FILE:LINE: ...") unless `file` starts with a
/// well-formed PLY 1.0 header whose elements fit in the bytes after it, and
/// has no `tristrips` element (assimp keeps one triangle of each strip).
void checkPlyHeader(const std::filesystem::path& file);

} // namespace vkrt
