#include "mesh/FileMaterials.h"

#include "util/Error.h"

#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

namespace vkrt {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

[[noreturn]] void fail(const fs::path& file, const std::string& message)
{
    throw InputError(file.string() + ": " + message);
}

/// glTF URIs are RFC 3986: "my%20wood.png" is the file "my wood.png".
std::string percentDecoded(const std::string& uri)
{
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        unsigned code = 0;
        if (uri[i] == '%' && i + 2 < uri.size()) {
            const auto [end, error] = std::from_chars(uri.data() + i + 1, uri.data() + i + 3, code, 16);
            if (error == std::errc() && end == uri.data() + i + 3) {
                out.push_back(char(code));
                i += 2;
                continue;
            }
        }
        out.push_back(uri[i]);
    }
    return out;
}

// ---------------------------------------------------------------------------
// JSON access that never throws on a wrong type: the file is whatever bytes
// it is, and assimp has accepted it, which says little about its other fields.

const json* member(const json& object, const char* key)
{
    if (!object.is_object()) return nullptr;
    const auto found = object.find(key);
    return found == object.end() ? nullptr : &*found;
}

const json* arrayMember(const json& object, const char* key)
{
    const json* value = member(object, key);
    return value && value->is_array() ? value : nullptr;
}

/// rapidjson's IsUint, which assimp's FindUInt uses: a non-negative integer below 2^32.
std::optional<uint32_t> uintMember(const json& object, const char* key)
{
    const json* value = member(object, key);
    if (!value || !value->is_number_unsigned()) return std::nullopt;
    const uint64_t number = value->get<uint64_t>();
    if (number > std::numeric_limits<uint32_t>::max()) return std::nullopt;
    return uint32_t(number);
}

const json* element(const json* array, uint32_t index)
{
    return array && index < array->size() ? &(*array)[index] : nullptr;
}

/// The names of an object's "extensions" members.
std::vector<std::string> extensionNames(const json& object)
{
    std::vector<std::string> names;
    if (const json* extensions = member(object, "extensions"); extensions && extensions->is_object())
        for (const auto& [name, value] : extensions->items()) names.push_back(name);
    return names;
}

std::vector<std::string> stringList(const json& doc, const char* key)
{
    std::vector<std::string> strings;
    if (const json* list = arrayMember(doc, key))
        for (const json& each : *list)
            if (each.is_string()) strings.push_back(each.get<std::string>());
    return strings;
}

/// Bytes above 0x7f as '?'. They can only stand inside JSON strings;
/// assimp's rapidjson takes them without checking their encoding and
/// nlohmann's parser refuses bad UTF-8, so both see one structure only when
/// they are masked (names are compared masked too).
std::string masked(std::string text)
{
    for (char& c : text)
        if (static_cast<unsigned char>(c) > 0x7f) c = '?';
    return text;
}

/// The byte offset of the first '[' or '{' that opens level `limit` + 1, if
/// any (strings skipped). Assimp's rapidjson parses recursively: about 100,000
/// nested arrays overflow the stack, so deep nesting is refused before it.
std::optional<size_t> findExcessiveNesting(std::string_view text, size_t limit)
{
    size_t depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) return i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return std::nullopt;
}

/// The file's JSON as assimp reads it. Duplicate keys are refused: rapidjson
/// takes the first, nlohmann the last, and bounds checked on one value
/// would not protect reads of the other.
json parseJson(const fs::path& file)
{
    const std::string text = masked(readGltfJson(file));
    if (const auto offset = findExcessiveNesting(text, kMaxGltfJsonNesting))
        fail(file, "the glTF JSON nests arrays and objects more than " + std::to_string(kMaxGltfJsonNesting) +
                       " levels deep (at byte " + std::to_string(*offset) + " of the JSON)");
    std::vector<std::set<std::string>> keys;
    std::string duplicate;
    const json::parser_callback_t noteKeys = [&](int, json::parse_event_t event, json& parsed) {
        if (event == json::parse_event_t::object_start) keys.emplace_back();
        if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
        if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string() &&
            !keys.back().insert(parsed.get<std::string>()).second && duplicate.empty())
            duplicate = parsed.get<std::string>();
        return true;
    };
    json doc = json::parse(text, noteKeys, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_object()) fail(file, "the glTF JSON cannot be parsed");
    if (!duplicate.empty()) fail(file, "the glTF JSON has the key '" + duplicate + "' twice in one object");
    return doc;
}

// ---------------------------------------------------------------------------
// Which file material is which aiMaterial. Assimp 5.2.5's glTF2 reader
// creates objects lazily, in the order the default scene reaches them
// (Asset::Load: scenes[scene] -> nodes, children before a node's own mesh
// -> meshes -> primitives' materials; then every skin's joints; then every
// animation channel's target node), and its aiMaterial i is the i-th material
// so reached, not the file's i-th. This walk repeats that order.

class MaterialOrder {
public:
    explicit MaterialOrder(const json& doc) : m_doc(doc) {}

    std::vector<uint32_t> walk()
    {
        const uint32_t sceneIndex = uintMember(m_doc, "scene").value_or(0);
        if (const json* scene = element(arrayMember(m_doc, "scenes"), sceneIndex))
            visitNodeList(arrayMember(*scene, "nodes"));
        if (const json* skins = arrayMember(m_doc, "skins"))
            for (const json& skin : *skins) visitNodeList(arrayMember(skin, "joints"));
        if (const json* animations = arrayMember(m_doc, "animations"))
            for (const json& animation : *animations) visitChannels(animation);
        return m_materials;
    }

private:
    void visitNodeList(const json* list)
    {
        if (!list) return;
        for (const json& node : *list)
            if (node.is_number_unsigned() && node.get<uint64_t>() <= std::numeric_limits<uint32_t>::max())
                visitNode(uint32_t(node.get<uint64_t>()));
    }

    void visitChannels(const json& animation)
    {
        if (const json* channels = arrayMember(animation, "channels"))
            for (const json& channel : *channels)
                if (const json* target = member(channel, "target"); target && target->is_object())
                    if (const auto node = uintMember(*target, "node")) visitNode(*node);
    }

    /// Depth first, a node's children before its mesh, without recursion (a
    /// file may nest nodes deeply; assimp refuses cycles before we get here).
    void visitNode(uint32_t root)
    {
        struct Pending {
            uint32_t node;
            size_t nextChild;
        };
        std::vector<Pending> stack;
        if (enter(root)) stack.push_back({root, 0});
        while (!stack.empty()) {
            Pending& top = stack.back();
            const json* node = element(arrayMember(m_doc, "nodes"), top.node);
            const json* children = node ? arrayMember(*node, "children") : nullptr;
            if (children && top.nextChild < children->size()) {
                const json& child = (*children)[top.nextChild++];
                if (child.is_number_unsigned() && child.get<uint64_t>() <= std::numeric_limits<uint32_t>::max() &&
                    enter(uint32_t(child.get<uint64_t>())))
                    stack.push_back({uint32_t(child.get<uint64_t>()), 0});
                continue;
            }
            if (node)
                if (const auto mesh = uintMember(*node, "mesh")) visitMesh(*mesh);
            stack.pop_back();
        }
    }

    bool enter(uint32_t node) { return m_nodes.insert(node).second; }

    void visitMesh(uint32_t index)
    {
        if (!m_meshes.insert(index).second) return;
        const json* mesh = element(arrayMember(m_doc, "meshes"), index);
        const json* primitives = mesh ? arrayMember(*mesh, "primitives") : nullptr;
        if (!primitives) return;
        for (const json& primitive : *primitives)
            if (const auto material = uintMember(primitive, "material"))
                if (m_seen.insert(*material).second) m_materials.push_back(*material);
    }

    const json& m_doc;
    std::set<uint32_t> m_nodes, m_meshes, m_seen;
    std::vector<uint32_t> m_materials;
};

// ---------------------------------------------------------------------------
// What vkrt will not honour, from the JSON (assimp keeps no list of the
// extensions it read, and drops those it does not know).

struct TextureSlot {
    const char* name; ///< as glTF names it
    bool inPbr;       ///< under pbrMetallicRoughness
    bool honoured;    ///< false: occlusionTexture (FileMaterials.h)
};

constexpr TextureSlot kTextureSlots[] = {
    {"baseColorTexture", true, true}, {"metallicRoughnessTexture", true, true}, {"normalTexture", false, true},
    {"emissiveTexture", false, true}, {"occlusionTexture", false, false},
};

const json* textureInfo(const json& material, const TextureSlot& slot)
{
    const json* owner = slot.inPbr ? member(material, "pbrMetallicRoughness") : &material;
    const json* info = owner ? member(*owner, slot.name) : nullptr;
    return info && info->is_object() ? info : nullptr;
}

/// Every extension a material or its texture references names.
std::set<std::string> materialExtensions(const json& material)
{
    std::set<std::string> names;
    for (const std::string& name : extensionNames(material)) names.insert(name);
    if (const json* pbr = member(material, "pbrMetallicRoughness"))
        for (const std::string& name : extensionNames(*pbr)) names.insert(name);
    for (const TextureSlot& slot : kTextureSlots)
        if (const json* info = textureInfo(material, slot))
            for (const std::string& name : extensionNames(*info)) names.insert(name);
    return names;
}

void listTextureProblems(const json& material, std::vector<std::string>& out)
{
    for (const TextureSlot& slot : kTextureSlots) {
        const json* info = textureInfo(material, slot);
        if (!info || !slot.honoured) continue;
        for (const std::string& name : extensionNames(*info))
            if (name != "KHR_texture_transform") out.push_back(name + " on " + slot.name + ": not applied");
        const json* extensions = member(*info, "extensions");
        const json* transform = extensions ? member(*extensions, "KHR_texture_transform") : nullptr;
        if (const json* texCoord = transform ? member(*transform, "texCoord") : nullptr;
            texCoord && texCoord->is_number_integer() && texCoord->get<int64_t>() != 0)
            out.push_back(std::string("KHR_texture_transform on ") + slot.name + " reads TEXCOORD_" +
                          std::to_string(texCoord->get<int64_t>()) + ": vkrt reads only TEXCOORD_0");
        if (const json* texCoord = member(*info, "texCoord");
            texCoord && texCoord->is_number_integer() && texCoord->get<int64_t>() != 0)
            out.push_back(std::string(slot.name) + " reads TEXCOORD_" + std::to_string(texCoord->get<int64_t>()) +
                          ": vkrt reads only TEXCOORD_0");
    }
}

/// Material extensions vkrt honours (readHonouredExtensions).
bool honouredMaterialExtension(const std::string& name)
{
    return name == "KHR_materials_emissive_strength" || name == "KHR_materials_transmission" ||
           name == "KHR_materials_ior";
}

/// The unsupported list of one file material (before the file's own extensions).
std::vector<std::string> materialProblems(const json& material)
{
    std::vector<std::string> out;
    for (const std::string& name : extensionNames(material))
        if (!honouredMaterialExtension(name)) out.push_back(name + ": material extension not supported");
    if (const json* extensions = member(material, "extensions"))
        if (const json* transmission = member(*extensions, "KHR_materials_transmission"))
            if (member(*transmission, "transmissionTexture"))
                out.push_back("KHR_materials_transmission's transmissionTexture: not applied (its factor is)");
    if (const json* pbr = member(material, "pbrMetallicRoughness"))
        for (const std::string& name : extensionNames(*pbr))
            out.push_back(name + " on pbrMetallicRoughness: not supported");
    listTextureProblems(material, out);
    return out;
}

/// Extensions the file uses or requires that no material names (lights,
/// mesh compression, ...): every material lists them, so none is silent.
std::vector<std::string> fileProblems(const json& doc)
{
    std::set<std::string> inMaterials;
    if (const json* materials = arrayMember(doc, "materials"))
        for (const json& material : *materials) inMaterials.merge(materialExtensions(material));
    std::set<std::string> fileLevel;
    for (const char* key : {"extensionsRequired", "extensionsUsed"})
        for (const std::string& name : stringList(doc, key))
            if (!inMaterials.count(name)) fileLevel.insert(name);
    std::vector<std::string> out;
    for (const std::string& name : fileLevel) out.push_back(name + ": file extension not supported");
    return out;
}

// ---------------------------------------------------------------------------
// aiMaterial -> FileMaterial: the values, as assimp 5.2.5's glTF2 importer
// stores them (ImportMaterial: BASE_COLOR, METALLIC_FACTOR, ROUGHNESS_FACTOR,
// textures under aiTextureType_BASE_COLOR, METALNESS (the metallicRoughness
// image, also under DIFFUSE_ROUGHNESS and UNKNOWN), NORMALS, EMISSIVE).

struct MaterialReader {
    const aiScene& scene;
    const fs::path& file;
    std::string materialName; ///< for messages
    const ReferencePolicy& references;

    [[noreturn]] void malformed(const std::string& what) const { fail(file, "material " + materialName + ": " + what); }

    float factor(const aiMaterial& m, const char* key, unsigned type, unsigned index, float fallback,
                 const char* gltfName) const
    {
        float value = fallback;
        if (m.Get(key, type, index, value) != AI_SUCCESS) return fallback;
        if (!std::isfinite(value) || value < 0.0f || value > 1.0f)
            malformed(std::string(gltfName) + " " + std::to_string(value) + " is outside [0, 1]");
        return value;
    }

    glm::vec4 colour(const aiMaterial& m, const char* key, unsigned type, unsigned index, glm::vec4 fallback,
                     const char* gltfName, bool unbounded) const
    {
        aiColor4D c;
        if (m.Get(key, type, index, c) != AI_SUCCESS) return fallback;
        const glm::vec4 value(c.r, c.g, c.b, c.a);
        for (int i = 0; i < 4; ++i)
            if (!std::isfinite(value[i]) || value[i] < 0.0f || (!unbounded && value[i] > 1.0f))
                malformed(std::string(gltfName) + " has a component " + std::to_string(value[i]) +
                          (unbounded ? " that is negative or not finite" : " outside [0, 1]"));
        return value;
    }

    std::optional<FileTexture> texture(const aiMaterial& m, aiTextureType type) const
    {
        aiString path;
        if (m.GetTextureCount(type) == 0 || m.Get(AI_MATKEY_TEXTURE(type, 0), path) != AI_SUCCESS) return std::nullopt;
        FileTexture texture;
        const std::string uri(path.C_Str(), path.length);
        if (!uri.empty() && uri[0] == '*') {
            embed(texture, uri);
        } else {
            if (uri.empty()) malformed("an image has neither a file nor base64 data");
            texture.file = file.parent_path() / percentDecoded(uri);
            references.check(texture.file, uri, "material " + materialName + "'s image");
            texture.name = texture.file.string();
        }
        texture.wrapU = wrap(m, AI_MATKEY_MAPPINGMODE_U(type, 0));
        texture.wrapV = wrap(m, AI_MATKEY_MAPPINGMODE_V(type, 0));
        return texture;
    }

    /// "*N": assimp's reference to its embedded texture N (a .glb's bufferView or a data: URI).
    void embed(FileTexture& texture, const std::string& reference) const
    {
        unsigned index = 0;
        const auto [end, error] = std::from_chars(reference.data() + 1, reference.data() + reference.size(), index);
        if (error != std::errc() || end != reference.data() + reference.size() || index >= scene.mNumTextures ||
            !scene.mTextures[index])
            malformed("names embedded image '" + reference + "', which the file does not have");
        const aiTexture& image = *scene.mTextures[index];
        // glTF images are always compressed (PNG, JPEG): assimp then gives the bytes, mHeight 0, mWidth bytes.
        if (image.mHeight != 0 || !image.pcData) malformed("embedded image " + std::to_string(index) + " has no data");
        const auto* bytes = reinterpret_cast<const uint8_t*>(image.pcData);
        texture.embedded.assign(bytes, bytes + image.mWidth);
        texture.name = file.string() + " (embedded image " + std::to_string(index) + ")";
    }

    static TextureWrap wrap(const aiMaterial& m, const char* key, unsigned type, unsigned index)
    {
        int mode = aiTextureMapMode_Wrap;
        m.Get(key, type, index, mode);
        if (mode == aiTextureMapMode_Clamp) return TextureWrap::Clamp;
        if (mode == aiTextureMapMode_Mirror) return TextureWrap::Mirror;
        return TextureWrap::Repeat; // glTF's default sampler
    }

    AlphaMode alphaMode(const aiMaterial& m) const
    {
        aiString mode;
        if (m.Get(AI_MATKEY_GLTF_ALPHAMODE, mode) != AI_SUCCESS) return AlphaMode::Opaque;
        const std::string text = mode.C_Str();
        if (text == "MASK") return AlphaMode::Mask;
        if (text == "BLEND") return AlphaMode::Blend;
        return AlphaMode::Opaque;
    }

    float positive(const aiMaterial& m, const char* key, unsigned type, unsigned index, float fallback,
                   const char* gltfName) const
    {
        float value = fallback;
        if (m.Get(key, type, index, value) != AI_SUCCESS) return fallback;
        if (!std::isfinite(value) || value < 0.0f)
            malformed(std::string(gltfName) + " " + std::to_string(value) + " is negative or not finite");
        return value;
    }

    FileMaterial convert(const aiMaterial& m) const
    {
        FileMaterial out;
        aiString name;
        if (m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
        out.baseColorFactor =
            colour(m, AI_MATKEY_BASE_COLOR, out.baseColorFactor, "baseColorFactor", /*unbounded=*/false);
        out.baseColorTexture = texture(m, aiTextureType_BASE_COLOR);
        if (!out.baseColorTexture) out.baseColorTexture = texture(m, aiTextureType_DIFFUSE);
        out.metallicFactor = factor(m, AI_MATKEY_METALLIC_FACTOR, out.metallicFactor, "metallicFactor");
        out.roughnessFactor = factor(m, AI_MATKEY_ROUGHNESS_FACTOR, out.roughnessFactor, "roughnessFactor");
        out.metallicRoughnessTexture = texture(m, aiTextureType_METALNESS);
        if (!out.metallicRoughnessTexture) out.metallicRoughnessTexture = texture(m, aiTextureType_UNKNOWN);
        out.normalTexture = texture(m, aiTextureType_NORMALS);
        out.normalScale = 1.0f;
        if (m.Get(AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0), out.normalScale) == AI_SUCCESS &&
            !std::isfinite(out.normalScale))
            malformed("normalTexture scale is not finite");
        out.emissiveFactor = glm::vec3(colour(m, AI_MATKEY_COLOR_EMISSIVE, glm::vec4(0.0f), "emissiveFactor",
                                              /*unbounded=*/true));
        out.emissiveTexture = texture(m, aiTextureType_EMISSIVE);
        out.alphaMode = alphaMode(m);
        out.alphaCutoff = positive(m, AI_MATKEY_GLTF_ALPHACUTOFF, out.alphaCutoff, "alphaCutoff");
        m.Get(AI_MATKEY_TWOSIDED, out.doubleSided);
        return out;
    }
};

/// "0 'Cube'", "2", "'Cube'" (index unknown) or "(glTF's default)": how messages name a material.
std::string describeMaterial(bool isDefault, int fileIndex, const std::string& name)
{
    if (isDefault) return "(glTF's default)";
    const std::string quoted = name.empty() ? "" : "'" + name + "'";
    if (fileIndex < 0) return quoted.empty() ? "(unnamed)" : quoted;
    return std::to_string(fileIndex) + (quoted.empty() ? "" : " " + quoted);
}

bool isGltf2(const json& doc)
{
    const json* asset = member(doc, "asset");
    const json* version = asset ? member(*asset, "version") : nullptr;
    return version && version->is_string() && version->get<std::string>().rfind("2", 0) == 0;
}

/// Whether `order` (the walk's file indices) fits assimp's materials: as many, and the same names.
bool orderMatches(const aiScene& scene, const std::vector<uint32_t>& order, const json* materials)
{
    if (scene.mNumMaterials == 0 || order.size() != scene.mNumMaterials - 1) return false;
    for (size_t i = 0; i < order.size(); ++i) {
        const json* material = element(materials, order[i]);
        if (!material || !scene.mMaterials[i]) return false;
        aiString name;
        scene.mMaterials[i]->Get(AI_MATKEY_NAME, name);
        const json* fileName = member(*material, "name");
        const std::string expected = fileName && fileName->is_string() ? fileName->get<std::string>() : "";
        if (expected != masked(name.C_Str())) return false;
    }
    return true;
}

void appendUnique(std::vector<std::string>& list, const std::vector<std::string>& more)
{
    for (const std::string& each : more)
        if (std::find(list.begin(), list.end(), each) == list.end()) list.push_back(each);
}

} // namespace

std::string readGltfJson(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) fail(file, "cannot open the glTF file");
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (bytes.compare(0, 4, "glTF") != 0) return bytes;
    // .glb: a 12-byte header (magic, version, length), then chunks of (length, type, data); JSON comes first.
    const auto word = [&](size_t offset) {
        uint32_t value = 0;
        if (offset + 4 <= bytes.size()) std::memcpy(&value, bytes.data() + offset, 4);
        return value;
    };
    constexpr uint32_t kJsonChunk = 0x4E4F534A; // "JSON", little endian
    const uint64_t length = word(12);
    if (bytes.size() < 20 || word(16) != kJsonChunk || 20 + length > bytes.size())
        fail(file, "the binary glTF's first chunk is not a whole JSON chunk");
    return bytes.substr(20, size_t(length));
}

namespace {

/// A non-negative integer field, or `fallback` when absent or of another type.
uint64_t sizeField(const json& object, const char* key, uint64_t fallback)
{
    const json* value = member(object, key);
    return value && value->is_number_unsigned() ? value->get<uint64_t>() : fallback;
}

/// Bytes of one accessor element (matrix column padding ignored: it only makes the need larger).
uint64_t elementBytes(const json& accessor)
{
    const uint64_t component = [&]() -> uint64_t {
        switch (sizeField(accessor, "componentType", 0)) {
        case 5120:
        case 5121: return 1;
        case 5122:
        case 5123: return 2;
        case 5125:
        case 5126: return 4;
        default: return 0;
        }
    }();
    const json* type = member(accessor, "type");
    const std::string name = type && type->is_string() ? type->get<std::string>() : "";
    const std::pair<const char*, uint64_t> counts[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                                                       {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    for (const auto& [typeName, count] : counts)
        if (name == typeName) return component * count;
    return 0;
}

} // namespace

namespace {

void checkBufferBounds(const fs::path& file, const json& doc)
{
    const json* buffers = arrayMember(doc, "buffers");
    const json* views = arrayMember(doc, "bufferViews");
    constexpr uint64_t kHuge = uint64_t(1) << 40; // no sum or product below overflows
    if (views) {
        for (uint32_t v = 0; v < views->size(); ++v) {
            const json& view = (*views)[v];
            const json* buffer =
                element(buffers, uint32_t(std::min<uint64_t>(sizeField(view, "buffer", 0), UINT32_MAX)));
            if (!buffer) continue;
            const uint64_t end =
                std::min(sizeField(view, "byteOffset", 0), kHuge) + std::min(sizeField(view, "byteLength", 0), kHuge);
            const uint64_t length = sizeField(*buffer, "byteLength", 0);
            if (end > length)
                fail(file, "bufferView " + std::to_string(v) + " ends at byte " + std::to_string(end) +
                               " of a buffer of " + std::to_string(length) + " bytes");
        }
    }
    const json* accessors = arrayMember(doc, "accessors");
    if (!accessors) return;
    for (uint32_t a = 0; a < accessors->size(); ++a) {
        const json& accessor = (*accessors)[a];
        const auto viewIndex = uintMember(accessor, "bufferView");
        const json* view = viewIndex ? element(views, *viewIndex) : nullptr;
        const uint64_t count = std::min(sizeField(accessor, "count", 0), kHuge);
        const uint64_t bytes = elementBytes(accessor);
        if (!view || count == 0 || bytes == 0) continue;
        const uint64_t stride = std::min(std::max(sizeField(*view, "byteStride", bytes), bytes), uint64_t(1) << 16);
        const uint64_t end = std::min(sizeField(accessor, "byteOffset", 0), kHuge) + (count - 1) * stride + bytes;
        const uint64_t length = sizeField(*view, "byteLength", 0);
        if (end > length)
            fail(file, "accessor " + std::to_string(a) + " needs " + std::to_string(end) + " bytes of bufferView " +
                           std::to_string(*viewIndex) + ", which has " + std::to_string(length));
    }
}

/// A child index as assimp reads it, or nullopt (assimp reports those itself).
std::optional<uint32_t> nodeIndex(const json& value, size_t nodeCount)
{
    if (!value.is_number_unsigned() || value.get<uint64_t>() >= nodeCount) return std::nullopt;
    return uint32_t(value.get<uint64_t>());
}

constexpr uint32_t kNoParent = UINT32_MAX;

/// Each node's parent (glTF: at most one), from the children lists.
std::vector<uint32_t> nodeParents(const fs::path& file, const json& nodes)
{
    std::vector<uint32_t> parent(nodes.size(), kNoParent);
    for (uint32_t node = 0; node < nodes.size(); ++node) {
        const json* children = arrayMember(nodes[node], "children");
        if (!children) continue;
        for (const json& each : *children) {
            const auto child = nodeIndex(each, nodes.size());
            if (!child) continue;
            if (*child == node) fail(file, "node " + std::to_string(node) + " lists itself among its children");
            if (parent[*child] == node)
                fail(file, "node " + std::to_string(node) + " lists node " + std::to_string(*child) +
                               " twice among its children");
            if (parent[*child] != kNoParent)
                fail(file, "node " + std::to_string(*child) + " is a child of both node " +
                               std::to_string(parent[*child]) + " and node " + std::to_string(node) +
                               " (glTF nodes form trees: each has at most one parent)");
            parent[*child] = node;
        }
    }
    return parent;
}

/// Refuses cycles and hierarchies deeper than kMaxGltfNodeDepth, walking up
/// the parent links without recursion: assimp 5.2.5 recurses once per level
/// (reading, importing, pre-transforming and freeing nodes) and overflows its
/// stack on a chain of 30,000 nodes. Each node's depth is computed once.
std::vector<uint32_t> checkNodeHierarchy(const fs::path& file, const json& doc)
{
    const json* nodes = arrayMember(doc, "nodes");
    if (!nodes) return {};
    std::vector<uint32_t> parent = nodeParents(file, *nodes);
    std::vector<uint32_t> depth(nodes->size(), 0);  // 0: not known yet; a root is 1
    std::vector<bool> onPath(nodes->size(), false); // on the current walk up
    std::vector<uint32_t> path;
    for (uint32_t start = 0; start < nodes->size(); ++start) {
        uint32_t node = start;
        for (path.clear(); node != kNoParent && depth[node] == 0 && !onPath[node]; node = parent[node]) {
            onPath[node] = true;
            path.push_back(node);
        }
        if (node != kNoParent && onPath[node])
            fail(file, "node " + std::to_string(node) + " is its own ancestor (its children lists form a cycle)");
        uint32_t level = node == kNoParent ? 0 : depth[node];
        for (auto it = path.rbegin(); it != path.rend(); ++it) {
            depth[*it] = ++level;
            onPath[*it] = false;
            if (level > kMaxGltfNodeDepth)
                fail(file, "node " + std::to_string(*it) + " is nested " + std::to_string(level) +
                               " levels deep in the node hierarchy; vkrt reads at most " +
                               std::to_string(kMaxGltfNodeDepth) + " levels");
        }
    }
    return parent;
}

// ---------------------------------------------------------------------------
// What the import will cost. Assimp reads a node once per time its scene
// reaches it, and PreTransformVertices gives every node naming a mesh its
// own copy of the mesh: a small file naming one large mesh from many nodes
// asks for memory without bound. Counted here from the JSON alone.

uint64_t saturatingAdd(uint64_t a, uint64_t b)
{
    uint64_t sum = 0;
    return __builtin_add_overflow(a, b, &sum) ? UINT64_MAX : sum;
}

uint64_t saturatingMultiply(uint64_t a, uint64_t b)
{
    uint64_t product = 0;
    return __builtin_mul_overflow(a, b, &product) ? UINT64_MAX : product;
}

/// 3456789012 as "3,456,789,012".
std::string withThousands(uint64_t value)
{
    std::string digits = std::to_string(value);
    for (size_t at = digits.size(); at > 3; at -= 3) digits.insert(at - 3, ",");
    return digits;
}

/// An accessor's `count` (clamped far above any bound), or 0 when `index` names none.
uint64_t accessorCount(const json* accessors, std::optional<uint32_t> index)
{
    const json* accessor = index ? element(accessors, *index) : nullptr;
    return accessor ? std::min(sizeField(*accessor, "count", 0), uint64_t(1) << 40) : 0;
}

/// The triangles one primitive gives: glTF modes 4 TRIANGLES (the default),
/// 5 TRIANGLE_STRIP and 6 TRIANGLE_FAN; points and lines (0-3) give none.
uint64_t primitiveTriangles(const json& primitive, const json* accessors)
{
    const json* attributes = member(primitive, "attributes");
    const uint64_t count =
        member(primitive, "indices")
            ? accessorCount(accessors, uintMember(primitive, "indices"))
            : accessorCount(accessors, attributes ? uintMember(*attributes, "POSITION") : std::nullopt);
    switch (uintMember(primitive, "mode").value_or(4)) {
    case 4: return count / 3;
    case 5:
    case 6: return count >= 3 ? count - 2 : 0;
    default: return 0;
    }
}

std::vector<uint64_t> meshTriangles(const json& doc)
{
    const json* meshes = arrayMember(doc, "meshes");
    const json* accessors = arrayMember(doc, "accessors");
    std::vector<uint64_t> triangles(meshes ? meshes->size() : 0, 0);
    for (size_t m = 0; m < triangles.size(); ++m)
        if (const json* primitives = arrayMember((*meshes)[m], "primitives"))
            for (const json& primitive : *primitives)
                triangles[m] = saturatingAdd(triangles[m], primitiveTriangles(primitive, accessors));
    return triangles;
}

/// How many times the import reaches each node: once per listing of it or
/// of an ancestor among the roots of the scene assimp imports (`scene`, or
/// 0). Parents come before children in a walk down from the forest's roots.
std::vector<uint64_t> importsPerNode(const json& doc, const json& nodes, const std::vector<uint32_t>& parent)
{
    std::vector<uint64_t> times(nodes.size(), 0);
    const json* scene = element(arrayMember(doc, "scenes"), uintMember(doc, "scene").value_or(0));
    if (const json* roots = scene ? arrayMember(*scene, "nodes") : nullptr)
        for (const json& each : *roots)
            if (const auto root = nodeIndex(each, nodes.size())) times[*root] = saturatingAdd(times[*root], 1);
    std::vector<uint32_t> order;
    for (uint32_t node = 0; node < nodes.size(); ++node)
        if (parent[node] == kNoParent) order.push_back(node);
    for (size_t next = 0; next < order.size(); ++next) {
        const uint32_t node = order[next];
        if (const json* children = arrayMember(nodes[node], "children"))
            for (const json& each : *children)
                if (const auto child = nodeIndex(each, nodes.size())) {
                    times[*child] = saturatingAdd(times[*child], times[node]);
                    order.push_back(*child);
                }
    }
    return times;
}

/// Refuses a file whose import would read more than kMaxGltfNodes nodes or
/// make more than kMaxGltfTriangles triangles, naming the mesh that gives most.
void checkInstancing(const fs::path& file, const json& doc, const std::vector<uint32_t>& parent)
{
    const json* nodes = arrayMember(doc, "nodes");
    if (!nodes) return;
    if (nodes->size() > kMaxGltfNodes)
        fail(file, "the file has " + withThousands(nodes->size()) + " nodes; vkrt reads at most " +
                       withThousands(kMaxGltfNodes) + " (the glTF reader slows with the square of their number)");
    const std::vector<uint64_t> times = importsPerNode(doc, *nodes, parent);
    const std::vector<uint64_t> triangles = meshTriangles(doc);
    std::vector<uint64_t> instances(triangles.size(), 0);
    uint64_t importedNodes = 0, meshInstances = 0;
    for (uint32_t node = 0; node < nodes->size(); ++node) {
        importedNodes = saturatingAdd(importedNodes, times[node]);
        const auto mesh = uintMember((*nodes)[node], "mesh");
        if (!mesh || *mesh >= instances.size()) continue;
        instances[*mesh] = saturatingAdd(instances[*mesh], times[node]);
        meshInstances = saturatingAdd(meshInstances, times[node]);
    }
    if (importedNodes > kMaxGltfNodes)
        fail(file, "the scene imports " + withThousands(importedNodes) +
                       " nodes (a node listed more than once among its roots is imported each time, with its "
                       "children); vkrt reads at most " +
                       withThousands(kMaxGltfNodes));
    uint64_t total = 0;
    size_t largest = 0;
    for (size_t m = 0; m < triangles.size(); ++m) {
        const uint64_t made = saturatingMultiply(instances[m], triangles[m]);
        total = saturatingAdd(total, made);
        if (made > saturatingMultiply(instances[largest], triangles[largest])) largest = m;
    }
    if (total > kMaxGltfTriangles)
        fail(file, "the node hierarchy instances meshes " + withThousands(meshInstances) + " times, " +
                       withThousands(total) + " triangles in all (mesh " + std::to_string(largest) + ", " +
                       withThousands(triangles[largest]) + " triangles, " + withThousands(instances[largest]) +
                       " times); vkrt reads at most " + withThousands(kMaxGltfTriangles) +
                       " triangles after instancing");
}

/// The bytes of accessor data one reference asks assimp for: count x
/// element size, twice without a bufferView (zeros made, then copied).
uint64_t referencedBytes(const json* accessors, std::optional<uint32_t> index)
{
    const json* accessor = index ? element(accessors, *index) : nullptr;
    if (!accessor) return 0;
    const uint64_t bytes = saturatingMultiply(accessorCount(accessors, index), elementBytes(*accessor));
    return member(*accessor, "bufferView") ? bytes : saturatingMultiply(bytes, 2);
}

/// Every accessor an object's members name (mesh attributes, a morph target).
uint64_t namedAccessorBytes(const json* accessors, const json* object)
{
    uint64_t bytes = 0;
    if (object && object->is_object())
        for (const auto& [name, value] : object->items())
            if (value.is_number_unsigned() && value.get<uint64_t>() <= UINT32_MAX)
                bytes = saturatingAdd(bytes, referencedBytes(accessors, uint32_t(value.get<uint64_t>())));
    return bytes;
}

uint64_t meshAccessorBytes(const json& doc, const json* accessors)
{
    uint64_t bytes = 0;
    if (const json* meshes = arrayMember(doc, "meshes"))
        for (const json& mesh : *meshes)
            if (const json* primitives = arrayMember(mesh, "primitives"))
                for (const json& primitive : *primitives) {
                    bytes = saturatingAdd(bytes, namedAccessorBytes(accessors, member(primitive, "attributes")));
                    bytes = saturatingAdd(bytes, referencedBytes(accessors, uintMember(primitive, "indices")));
                    if (const json* targets = arrayMember(primitive, "targets"))
                        for (const json& target : *targets)
                            bytes = saturatingAdd(bytes, namedAccessorBytes(accessors, &target));
                }
    return bytes;
}

uint64_t skinAndAnimationAccessorBytes(const json& doc, const json* accessors)
{
    uint64_t bytes = 0;
    if (const json* skins = arrayMember(doc, "skins"))
        for (const json& skin : *skins)
            bytes = saturatingAdd(bytes, referencedBytes(accessors, uintMember(skin, "inverseBindMatrices")));
    if (const json* animations = arrayMember(doc, "animations"))
        for (const json& animation : *animations)
            if (const json* samplers = arrayMember(animation, "samplers"))
                for (const json& sampler : *samplers)
                    for (const char* key : {"input", "output"})
                        bytes = saturatingAdd(bytes, referencedBytes(accessors, uintMember(sampler, key)));
    return bytes;
}

/// Refuses accessor data beyond kMaxGltfAccessorBytes: an accessor lies
/// inside its buffer, but many references to it, or one without a buffer
/// (zeros with a sparse patch), ask for more than the file holds.
void checkAccessorUse(const fs::path& file, const json& doc)
{
    const json* accessors = arrayMember(doc, "accessors");
    const uint64_t bytes =
        saturatingAdd(meshAccessorBytes(doc, accessors), skinAndAnimationAccessorBytes(doc, accessors));
    if (bytes > kMaxGltfAccessorBytes)
        fail(file, "the meshes, morph targets, skins and animations use " + withThousands(bytes) +
                       " bytes of accessor data (each use counted, an accessor without a bufferView twice); vkrt "
                       "reads at most " +
                       withThousands(kMaxGltfAccessorBytes));
}

/// Every buffer and image the JSON names by a file URI (data: URIs need no file) must be one the policy allows.
void checkFileReferences(const fs::path& file, const json& doc, const ReferencePolicy& references)
{
    for (const char* kind : {"buffers", "images"}) {
        const json* list = arrayMember(doc, kind);
        if (!list) continue;
        for (size_t i = 0; i < list->size(); ++i) {
            const json* uri = member((*list)[i], "uri");
            if (!uri || !uri->is_string()) continue;
            const std::string text = uri->get<std::string>();
            if (text.rfind("data:", 0) == 0) continue;
            const std::string what = std::string(kind) == "buffers" ? "buffer " : "image ";
            references.check(file.parent_path() / percentDecoded(text), text, what + std::to_string(i));
        }
    }
}

} // namespace

void checkGltfBeforeImport(const fs::path& file, const ReferencePolicy& references)
{
    const json doc = parseJson(file);
    checkBufferBounds(file, doc);
    checkInstancing(file, doc, checkNodeHierarchy(file, doc));
    checkAccessorUse(file, doc);
    checkFileReferences(file, doc, references);
}

namespace {

/// A number of an extension object, checked to lie in [low, high], or `fallback`.
float extensionNumber(const fs::path& file, const json& extension, const char* extensionName, const char* key,
                      float fallback, float low, float high)
{
    const json* value = member(extension, key);
    if (!value) return fallback;
    if (!value->is_number() || !(value->get<double>() >= low && value->get<double>() <= high))
        fail(file, std::string(extensionName) + "." + key + ": must be a number in [" + std::to_string(low) + ", " +
                       std::to_string(high) + "]");
    return float(value->get<double>());
}

/// A texture's KHR_texture_transform (offset, rotation, scale), checked finite.
void readTextureTransform(const fs::path& file, const json* info, const char* slotName,
                          std::optional<FileTexture>& texture)
{
    const json* extensions = info ? member(*info, "extensions") : nullptr;
    const json* transform = extensions ? member(*extensions, "KHR_texture_transform") : nullptr;
    if (!transform || !texture) return;
    const std::string where = std::string(slotName) + ".extensions.KHR_texture_transform";
    auto pair = [&](const char* key, glm::dvec2 fallback) {
        const json* value = member(*transform, key);
        if (!value) return fallback;
        if (!value->is_array() || value->size() != 2 || !(*value)[0].is_number() || !(*value)[1].is_number() ||
            !std::isfinite((*value)[0].get<double>()) || !std::isfinite((*value)[1].get<double>()))
            fail(file, where + "." + key + ": expected two finite numbers");
        return glm::dvec2((*value)[0].get<double>(), (*value)[1].get<double>());
    };
    texture->offset = pair("offset", glm::dvec2(0.0));
    texture->scale = pair("scale", glm::dvec2(1.0));
    if (const json* rotation = member(*transform, "rotation")) {
        if (!rotation->is_number() || !std::isfinite(rotation->get<double>()))
            fail(file, where + ".rotation: expected a finite number");
        texture->rotation = rotation->get<double>();
    }
}

/// KHR_materials_emissive_strength, _transmission and _ior from the
/// material's JSON, and its textures' KHR_texture_transform.
void readHonouredExtensions(const fs::path& file, const json& material, FileMaterial& out)
{
    const json* pbr = member(material, "pbrMetallicRoughness");
    readTextureTransform(file, pbr ? member(*pbr, "baseColorTexture") : nullptr, "baseColorTexture",
                         out.baseColorTexture);
    readTextureTransform(file, pbr ? member(*pbr, "metallicRoughnessTexture") : nullptr, "metallicRoughnessTexture",
                         out.metallicRoughnessTexture);
    readTextureTransform(file, member(material, "normalTexture"), "normalTexture", out.normalTexture);
    const json* extensions = member(material, "extensions");
    if (!extensions) return;
    if (const json* e = member(*extensions, "KHR_materials_emissive_strength"))
        out.emissiveFactor *= extensionNumber(file, *e, "KHR_materials_emissive_strength", "emissiveStrength", 1.0f,
                                              0.0f, std::numeric_limits<float>::max());
    if (const json* e = member(*extensions, "KHR_materials_transmission"))
        out.transmission =
            extensionNumber(file, *e, "KHR_materials_transmission", "transmissionFactor", 0.0f, 0.0f, 1.0f);
    if (const json* e = member(*extensions, "KHR_materials_ior")) {
        out.ior = extensionNumber(file, *e, "KHR_materials_ior", "ior", 1.5f, 0.0f, 1e30f);
        if (out.ior != 0.0f && out.ior < 1.0f)
            fail(file, "KHR_materials_ior.ior: must be 0 or at least 1, got " + std::to_string(out.ior));
        if (out.ior == 0.0f) out.ior = 1.5f; // glTF: 0 means the default dielectric; vkrt has no ideal metal here
    }
    if (!std::isfinite(out.emissiveFactor.r + out.emissiveFactor.g + out.emissiveFactor.b))
        fail(file, "emissiveFactor x KHR_materials_emissive_strength is beyond 32-bit float range");
}

} // namespace

std::vector<FileMaterial> readGltfMaterials(const aiScene& scene, const fs::path& file,
                                            const ReferencePolicy& references)
{
    const json doc = parseJson(file);
    if (!isGltf2(doc) || scene.mNumMaterials == 0) return {};
    const json* fileMaterials = arrayMember(doc, "materials");
    const std::vector<uint32_t> order = MaterialOrder(doc).walk();
    const bool matched = orderMatches(scene, order, fileMaterials);
    const std::vector<std::string> fileLevel = fileProblems(doc);
    // Unmatched (an assimp whose order differs from 5.2.5's): every material
    // lists what any file material uses, so that nothing is silent.
    std::vector<std::string> anyMaterial;
    if (!matched && fileMaterials)
        for (const json& material : *fileMaterials) appendUnique(anyMaterial, materialProblems(material));

    std::vector<FileMaterial> materials;
    for (unsigned i = 0; i < scene.mNumMaterials; ++i) {
        const bool isDefault = i + 1 == scene.mNumMaterials;
        const int fileIndex = matched && !isDefault ? int(order[i]) : -1;
        std::string name;
        if (scene.mMaterials[i]) {
            aiString aiName;
            scene.mMaterials[i]->Get(AI_MATKEY_NAME, aiName);
            name = aiName.C_Str();
        }
        const MaterialReader reader{scene, file, describeMaterial(isDefault, fileIndex, name), references};
        FileMaterial material = scene.mMaterials[i] ? reader.convert(*scene.mMaterials[i]) : FileMaterial{};
        material.fileIndex = fileIndex;
        if (fileIndex >= 0) {
            const json& source = *element(fileMaterials, uint32_t(fileIndex));
            material.unsupported = materialProblems(source);
            readHonouredExtensions(file, source, material);
        }
        if (!isDefault) appendUnique(material.unsupported, anyMaterial);
        appendUnique(material.unsupported, fileLevel);
        materials.push_back(std::move(material));
    }
    return materials;
}

} // namespace vkrt
