#pragma once
// Reading glTF's JSON without ever throwing on a wrong type: the file is
// whatever bytes it is, and nothing about one field says anything about
// another. Shared by the checks and materials (FileMaterials.cpp) and the
// reader (GltfReader.cpp).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace vkrt::gltf_json {

using nlohmann::json;

/// `object[key]`, or null when `object` is no object or has no such key.
inline const json* member(const json& object, const char* key)
{
    if (!object.is_object()) return nullptr;
    const auto found = object.find(key);
    return found == object.end() ? nullptr : &*found;
}

/// `object[key]` when it is an array, else null.
inline const json* arrayMember(const json& object, const char* key)
{
    const json* value = member(object, key);
    return value && value->is_array() ? value : nullptr;
}

/// A non-negative integer below 2^32 (glTF's indices and counts), else nullopt.
inline std::optional<uint32_t> uintMember(const json& object, const char* key)
{
    const json* value = member(object, key);
    if (!value || !value->is_number_unsigned() || value->get<uint64_t>() > UINT32_MAX) return std::nullopt;
    return uint32_t(value->get<uint64_t>());
}

/// `object[key]` when it is a string, else "".
inline std::string stringMember(const json& object, const char* key)
{
    const json* value = member(object, key);
    return value && value->is_string() ? value->get<std::string>() : "";
}

/// Bytes of one component of an accessor's componentType (glTF's WebGL
/// enums: byte, unsigned byte, short, unsigned short, unsigned int, float); 0 for another.
inline uint32_t componentBytes(uint64_t componentType)
{
    switch (componentType) {
    case 5120:
    case 5121: return 1;
    case 5122:
    case 5123: return 2;
    case 5125:
    case 5126: return 4;
    default: return 0;
    }
}

/// 3456789012 as "3,456,789,012", for counts in messages.
inline std::string withThousands(uint64_t value)
{
    std::string digits = std::to_string(value);
    for (size_t at = digits.size(); at > 3; at -= 3) digits.insert(at - 3, ",");
    return digits;
}

} // namespace vkrt::gltf_json
