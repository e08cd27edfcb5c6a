#pragma once
// The glTF 2.0 schema's rules on the types of the properties vkrt reads or
// counts with, checked over the whole document before anything trusts it:
// an index written 84.0, -84 or "84" is an error naming its path in the
// file (nodes[3].children[0]), not a property quietly taken as absent (a
// child, light or camera dropped, a byteOffset read as 0); enumerations
// (primitive modes, component types, sampler wraps; the material reader checks filters) hold only
// their listed values; every `extensions` is an object, every name in
// extensionsUsed and extensionsRequired a string.
#include <nlohmann/json_fwd.hpp>

#include <filesystem>

namespace vkrt {

/// Throws InputError naming the file and the property's path for the first
/// property of the wrong type or value. Linear in the document's size.
void checkGltfSchema(const std::filesystem::path& file, const nlohmann::json& doc);

} // namespace vkrt
