#include "mesh/GltfSchema.h"

#include "mesh/GltfJson.h"
#include "util/Error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace vkrt {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// What a property must be.
enum class Want {
    Index,   ///< an integer from 0 to 2^32 - 1 (indices, offsets)
    Count,   ///< an integer from 1 to 2^32 - 1 (counts, lengths)
    Stride,  ///< a byteStride: an integer from 4 to 252, a multiple of 4
    OneOf,   ///< one of `values`
    Array,   ///< an array
    Object,  ///< an object
    String,  ///< a string
    Boolean, ///< true or false
};

/// One rule: a path pattern and what the properties it matches must be.
/// Segments are separated by dots: `key` a member, `key[]` each element of
/// the array member `key`, `*` every member of an object, `*Texture` every
/// member whose name ends in "Texture", `**` any depth of members (none into
/// `extras`, which is the application's own).
struct Rule {
    std::string_view path;
    Want want;
    std::vector<int64_t> values = {}; ///< for OneOf
    std::string_view valuesName = {}; ///< for OneOf: "a primitive mode (0 to 6)"
};

const std::vector<Rule>& rules()
{
    static const std::vector<Rule> list = {
        // The top level's arrays.
        {"accessors", Want::Array},
        {"animations", Want::Array},
        {"buffers", Want::Array},
        {"bufferViews", Want::Array},
        {"cameras", Want::Array},
        {"images", Want::Array},
        {"materials", Want::Array},
        {"meshes", Want::Array},
        {"nodes", Want::Array},
        {"samplers", Want::Array},
        {"scenes", Want::Array},
        {"skins", Want::Array},
        {"textures", Want::Array},
        {"extensionsUsed", Want::Array},
        {"extensionsRequired", Want::Array},
        {"extensionsUsed[]", Want::String},
        {"extensionsRequired[]", Want::String},
        {"asset", Want::Object},
        {"asset.version", Want::String},
        {"scene", Want::Index},
        {"scenes[].nodes", Want::Array},
        {"scenes[].nodes[]", Want::Index},
        // Nodes.
        {"nodes[].camera", Want::Index},
        {"nodes[].skin", Want::Index},
        {"nodes[].mesh", Want::Index},
        {"nodes[].children", Want::Array},
        {"nodes[].children[]", Want::Index},
        {"nodes[].extensions.KHR_lights_punctual", Want::Object},
        {"nodes[].extensions.KHR_lights_punctual.light", Want::Index},
        {"nodes[].extensions.EXT_mesh_gpu_instancing.attributes", Want::Object},
        {"nodes[].extensions.EXT_mesh_gpu_instancing.attributes.*", Want::Index},
        // Meshes.
        {"meshes[].primitives", Want::Array},
        {"meshes[].primitives[].attributes", Want::Object},
        {"meshes[].primitives[].attributes.*", Want::Index},
        {"meshes[].primitives[].indices", Want::Index},
        {"meshes[].primitives[].material", Want::Index},
        {"meshes[].primitives[].mode", Want::OneOf, {0, 1, 2, 3, 4, 5, 6}, "a primitive mode (0 to 6)"},
        {"meshes[].primitives[].targets", Want::Array},
        {"meshes[].primitives[].targets[].*", Want::Index},
        {"meshes[].primitives[].extensions.KHR_materials_variants.mappings", Want::Array},
        {"meshes[].primitives[].extensions.KHR_materials_variants.mappings[].variants", Want::Array},
        {"meshes[].primitives[].extensions.KHR_materials_variants.mappings[].variants[]", Want::Index},
        {"meshes[].primitives[].extensions.KHR_materials_variants.mappings[].material", Want::Index},
        // Accessors, buffer views, buffers.
        {"accessors[].bufferView", Want::Index},
        {"accessors[].byteOffset", Want::Index},
        {"accessors[].componentType",
         Want::OneOf,
         {5120, 5121, 5122, 5123, 5125, 5126},
         "a component type (5120, 5121, 5122, 5123, 5125 or 5126)"},
        {"accessors[].normalized", Want::Boolean},
        {"accessors[].count", Want::Count},
        {"accessors[].type", Want::String},
        {"accessors[].sparse", Want::Object},
        {"accessors[].sparse.count", Want::Count},
        {"accessors[].sparse.indices", Want::Object},
        {"accessors[].sparse.indices.bufferView", Want::Index},
        {"accessors[].sparse.indices.byteOffset", Want::Index},
        {"accessors[].sparse.indices.componentType",
         Want::OneOf,
         {5121, 5123, 5125},
         "an unsigned index type (5121, 5123 or 5125)"},
        {"accessors[].sparse.values", Want::Object},
        {"accessors[].sparse.values.bufferView", Want::Index},
        {"accessors[].sparse.values.byteOffset", Want::Index},
        {"bufferViews[].buffer", Want::Index},
        {"bufferViews[].byteOffset", Want::Index},
        {"bufferViews[].byteLength", Want::Count},
        {"bufferViews[].byteStride", Want::Stride},
        {"bufferViews[].target", Want::OneOf, {34962, 34963}, "a buffer target (34962 or 34963)"},
        {"buffers[].byteLength", Want::Count},
        {"buffers[].uri", Want::String},
        // Images, textures, samplers, materials.
        {"images[].uri", Want::String},
        {"images[].mimeType", Want::String},
        {"images[].bufferView", Want::Index},
        {"textures[].sampler", Want::Index},
        {"textures[].source", Want::Index},
        {"textures[].extensions.*.source", Want::Index},
        // (magFilter and minFilter: the material reader refuses other values, naming the material too.)
        {"samplers[].wrapS", Want::OneOf, {33071, 33648, 10497}, "a wrap mode (33071, 33648 or 10497)"},
        {"samplers[].wrapT", Want::OneOf, {33071, 33648, 10497}, "a wrap mode (33071, 33648 or 10497)"},
        {"materials[].alphaMode", Want::String},
        {"materials[].doubleSided", Want::Boolean},
        {"materials[].**.*Texture", Want::Object},
        {"materials[].**.*Texture.index", Want::Index},
        {"materials[].**.*Texture.texCoord", Want::Index},
        {"materials[].**.*Texture.extensions.KHR_texture_transform.texCoord", Want::Index},
        // Cameras; skins and animations (not rendered, but their accessors are counted).
        {"cameras[].type", Want::String},
        {"skins[].inverseBindMatrices", Want::Index},
        {"skins[].skeleton", Want::Index},
        {"skins[].joints", Want::Array},
        {"skins[].joints[]", Want::Index},
        {"animations[].channels", Want::Array},
        {"animations[].channels[].sampler", Want::Index},
        {"animations[].channels[].target.node", Want::Index},
        {"animations[].samplers", Want::Array},
        {"animations[].samplers[].input", Want::Index},
        {"animations[].samplers[].output", Want::Index},
    };
    return list;
}

/// A value as the file wrote it, cut to 96 bytes for messages.
std::string shown(const json& value)
{
    std::string text = value.dump();
    if (text.size() > 96) text = text.substr(0, 93) + "...";
    return text;
}

bool isInteger(const json& value, int64_t low, int64_t high)
{
    if (value.is_number_unsigned())
        return value.get<uint64_t>() >= uint64_t(std::max<int64_t>(low, 0)) && value.get<uint64_t>() <= uint64_t(high);
    if (value.is_number_integer()) return value.get<int64_t>() >= low && value.get<int64_t>() <= high;
    return false; // 84.0 is a float here: glTF's integers are written without a fraction
}

void checkValue(const fs::path& file, const json& value, const Rule& rule, const std::string& where)
{
    constexpr int64_t kMaxIndex = UINT32_MAX;
    const auto fail = [&](const std::string& expected) {
        failInFile(file, where + ": expected " + expected + ", got " + shown(value));
    };
    switch (rule.want) {
    case Want::Index:
        if (!isInteger(value, 0, kMaxIndex)) fail("an integer from 0 to 4294967295 (glTF's indices and offsets)");
        return;
    case Want::Count:
        if (!isInteger(value, 1, kMaxIndex)) fail("an integer from 1 to 4294967295");
        return;
    case Want::Stride:
        if (!isInteger(value, 4, 252) || value.get<int64_t>() % 4 != 0)
            fail("a byteStride: an integer from 4 to 252, a multiple of 4");
        return;
    case Want::OneOf:
        if (!value.is_number_integer() ||
            std::find(rule.values.begin(), rule.values.end(), value.get<int64_t>()) == rule.values.end())
            fail(std::string(rule.valuesName));
        return;
    case Want::Array:
        if (!value.is_array()) fail("an array");
        return;
    case Want::Object:
        if (!value.is_object()) fail("an object");
        return;
    case Want::String:
        if (!value.is_string()) fail("a string");
        return;
    case Want::Boolean:
        if (!value.is_boolean()) fail("true or false");
        return;
    }
}

bool endsWith(std::string_view text, std::string_view suffix)
{
    return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// Applies `rule`'s remaining `path` below `value`, which sits at `where`.
void visit(const fs::path& file, const json& value, std::string_view path, const Rule& rule, const std::string& where)
{
    if (path.empty()) return checkValue(file, value, rule, where);
    const size_t dot = path.find('.');
    std::string_view segment = path.substr(0, dot);
    const std::string_view rest = dot == std::string_view::npos ? std::string_view() : path.substr(dot + 1);
    if (!value.is_object()) return; // an object's own rule reports it
    const auto prefix = [&](const std::string& key) { return where.empty() ? key : where + "." + key; };
    if (segment == "**") {
        visit(file, value, rest, rule, where); // zero levels
        for (const auto& [key, member] : value.items())
            if (key != "extras" && member.is_object()) visit(file, member, path, rule, prefix(key));
        return;
    }
    const bool each = endsWith(segment, "[]");
    if (each) segment.remove_suffix(2);
    const auto step = [&](const std::string& key, const json& member) {
        if (!each) return visit(file, member, rest, rule, prefix(key));
        if (!member.is_array()) return; // the array's own rule reports it
        for (size_t i = 0; i < member.size(); ++i)
            visit(file, member[i], rest, rule, prefix(key) + "[" + std::to_string(i) + "]");
    };
    if (segment.front() == '*') {
        const std::string_view suffix = segment.substr(1);
        for (const auto& [key, member] : value.items())
            if (key != "extras" && endsWith(key, suffix)) step(key, member);
        return;
    }
    if (const json* member = gltf_json::member(value, std::string(segment).c_str()))
        step(std::string(segment), *member);
}

/// Every `extensions` must be an object (an array hid its extensions from every reader).
void checkExtensionObjects(const fs::path& file, const json& value, const std::string& where)
{
    if (value.is_object()) {
        for (const auto& [key, member] : value.items()) {
            if (key == "extras") continue;
            const std::string path = where.empty() ? key : where + "." + key;
            if (key == "extensions" && !member.is_object())
                failInFile(file, path + ": expected an object, got " + shown(member));
            if (member.is_structured()) checkExtensionObjects(file, member, path);
        }
    } else if (value.is_array()) {
        for (size_t i = 0; i < value.size(); ++i)
            if (value[i].is_structured()) checkExtensionObjects(file, value[i], where + "[" + std::to_string(i) + "]");
    }
}

} // namespace

void checkGltfSchema(const fs::path& file, const json& doc)
{
    for (const Rule& rule : rules()) visit(file, doc, rule.path, rule, "");
    checkExtensionObjects(file, doc, "");
}

} // namespace vkrt
