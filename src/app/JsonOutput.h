#pragma once
// Machine-readable output of `vkrt render` and `vkrt info` (`--json FILE|-`,
// docs/machine-output.md): one JSON object per run, so that tools and scripts
// read facts instead of the lines printed for people, whose wording may change.
#include "io/OutputPaths.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace vkrt {

struct Scene;

/// The schema's version (docs/machine-output.md). Added fields keep it; a
/// field that is renamed, removed or changes its meaning or unit raises it.
inline constexpr int kMachineOutputSchema = 1;

/// Keys stay in the order they were added, the order the schema lists them.
using JsonObject = nlohmann::ordered_json;

/// The --json path as an output for checkOutputs: "-" (standard output) is no
/// file, so it is given as an empty path, which the checks skip.
NamedFile jsonOutputFile(const std::string& path);

/// The fields every document starts with: schema, command, vkrtVersion.
JsonObject jsonDocument(const std::string& command);

/// Writes `document` to `path` atomically (io/AtomicFile.h), or to standard
/// output for "-". Non-finite numbers become null (JSON has none). Throws
/// InputError naming --json when the write fails.
void writeJson(const std::string& path, const JsonObject& document);

/// A value, or null when there is none.
template <class T>
JsonObject valueOrNull(const std::optional<T>& value)
{
    return value ? JsonObject(*value) : JsonObject(nullptr);
}


} // namespace vkrt
