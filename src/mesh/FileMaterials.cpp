#include "mesh/FileMaterials.h"
#include "mesh/GltfSchema.h"

#include "mesh/GltfJson.h"
#include "util/Error.h"
#include "util/KernelLimits.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string_view>

namespace vkrt {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace gltf_json;

namespace {

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

/// Bytes above 0x7f as '?'. They can only stand inside JSON strings, and
/// nlohmann's parser refuses bad UTF-8: masked, such a file still parses
/// (parseJson tries the bytes as they are first).
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

/// The first key a JSON text has twice in one object, found by a SAX pass
/// in time linear in the text. (nlohmann's parser with a callback, used for
/// this before, scans an array's elements at the end of each object in it:
/// 300,000 empty nodes took 26 s.)
struct DuplicateKeyFinder : nlohmann::json_sax<json> {
    std::vector<std::set<std::string>> keys; ///< one set per open object
    std::string duplicate;

    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override
    {
        keys.emplace_back();
        return true;
    }
    bool key(string_t& name) override
    {
        if (!keys.back().insert(name).second && duplicate.empty()) duplicate = name;
        return true;
    }
    bool end_object() override
    {
        keys.pop_back();
        return true;
    }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }
};

/// The file's JSON. Duplicate keys are refused: parsers differ in which one
/// they keep (the first or the last), and a file that means two things to
/// two readers is no file to trust.
json parseJsonText(const fs::path& file, const std::string& text, bool mustParse)
{
    if (const auto offset = findExcessiveNesting(text, kMaxGltfJsonNesting))
        failInFile(file, "the glTF JSON nests arrays and objects more than " + std::to_string(kMaxGltfJsonNesting) +
                             " levels deep (at byte " + std::to_string(*offset) + " of the JSON)");
    json doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!mustParse && doc.is_discarded()) return doc;
    if (doc.is_discarded() || !doc.is_object()) failInFile(file, "the glTF JSON cannot be parsed");
    DuplicateKeyFinder finder;
    json::sax_parse(text, &finder);
    if (!finder.duplicate.empty())
        failInFile(file, "the glTF JSON has the key '" + finder.duplicate + "' twice in one object");
    return doc;
}

json parseJson(const fs::path& file)
{
    const std::string raw = readGltfJson(file);
    // glTF's JSON is UTF-8; a file with other bytes in its strings is read
    // with them masked rather than refused (names and messages show '?').
    json doc = parseJsonText(file, raw, /*mustParse=*/false);
    if (!doc.is_discarded()) return doc;
    return parseJsonText(file, masked(raw), /*mustParse=*/true);
}

// ---------------------------------------------------------------------------
// What vkrt will not honour of a material, from its JSON.

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

void listTextureProblems(const json& material, std::vector<std::string>& out)
{
    for (const TextureSlot& slot : kTextureSlots) {
        const json* info = textureInfo(material, slot);
        if (!info || !slot.honoured) continue;
        for (const std::string& name : extensionNames(*info))
            if (name != "KHR_texture_transform") out.push_back(name + " on " + slot.name + ": not applied");
    }
}

/// The unsupported list of one file material. Extensions themselves are
/// named once per file (GltfReader's extensionsUsed warning), not here.
std::vector<std::string> materialProblems(const json& material)
{
    std::vector<std::string> out;
    listTextureProblems(material, out);
    return out;
}

} // namespace

std::string readGltfJson(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) failInFile(file, "cannot open the glTF file");
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (bytes.compare(0, 4, "glTF") != 0) return bytes;
    // .glb: a 12-byte header (magic, version, length), then chunks of (length, type, data); JSON comes first.
    const auto word = [&](size_t offset) {
        uint32_t value = 0;
        if (offset + 4 <= bytes.size()) std::memcpy(&value, bytes.data() + offset, 4);
        return value;
    };
    constexpr uint32_t kJsonChunk = 0x4E4F534A; // "JSON", little endian
    // glTF 2.0, 4.4: version 2; the header's length is the file's; chunks start and end 4-byte aligned.
    if (bytes.size() < 12 || word(4) != 2)
        failInFile(file, "a binary glTF of container version " + std::to_string(word(4)) + ": vkrt reads version 2");
    if (word(8) != bytes.size())
        failInFile(file, "the binary glTF's header gives its length as " + std::to_string(word(8)) +
                             " bytes, but the file has " + std::to_string(bytes.size()));
    const uint64_t length = word(12);
    if (bytes.size() < 20 || word(16) != kJsonChunk || 20 + length > bytes.size())
        failInFile(file, "the binary glTF's first chunk is not a whole JSON chunk");
    if (length % 4 != 0)
        failInFile(file, "the binary glTF's JSON chunk is " + std::to_string(length) +
                             " bytes long, not a multiple of 4 (glTF pads it with spaces)");
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
    const uint64_t component = componentBytes(sizeField(accessor, "componentType", 0));
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
                failInFile(file, "bufferView " + std::to_string(v) + " ends at byte " + std::to_string(end) +
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
            failInFile(file, "accessor " + std::to_string(a) + " needs " + std::to_string(end) +
                                 " bytes of bufferView " + std::to_string(*viewIndex) + ", which has " +
                                 std::to_string(length));
    }
}

/// A child index, or nullopt for one that names no node (the reader reports those).
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
            if (*child == node) failInFile(file, "node " + std::to_string(node) + " lists itself among its children");
            if (parent[*child] == node)
                failInFile(file, "node " + std::to_string(node) + " lists node " + std::to_string(*child) +
                                     " twice among its children");
            if (parent[*child] != kNoParent)
                failInFile(file, "node " + std::to_string(*child) + " is a child of both node " +
                                     std::to_string(parent[*child]) + " and node " + std::to_string(node) +
                                     " (glTF nodes form trees: each has at most one parent)");
            parent[*child] = node;
        }
    }
    return parent;
}

/// Refuses cycles and hierarchies deeper than kMaxGltfNodeDepth, walking up
/// the parent links without recursion (a recursive reader, assimp 5.2.5's,
/// overflowed its stack on a chain of 30,000 nodes). Each node's depth is
/// computed once.
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
            failInFile(file, "node " + std::to_string(node) + " is its own ancestor (its children lists form a cycle)");
        uint32_t level = node == kNoParent ? 0 : depth[node];
        for (auto it = path.rbegin(); it != path.rend(); ++it) {
            depth[*it] = ++level;
            onPath[*it] = false;
            if (level > kMaxGltfNodeDepth)
                failInFile(file, "node " + std::to_string(*it) + " is nested " + std::to_string(level) +
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

/// How many times the reader reaches each node: once per listing of it or
/// of an ancestor among the roots of the default scene (`scene`, or 0;
/// another scene chosen with --scene is bounded by the reader's own walk). Parents come before children in a walk down
/// from the forest's roots.
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

/// Refuses a file whose scene would read more than kMaxGltfNodes nodes,
/// place meshes more than kMaxGltfInstances times, or whose placed meshes
/// hold more than kMaxGltfTriangles triangles (each mesh counted once: its
/// instances share it), naming the mesh that gives most.
void checkInstancing(const fs::path& file, const json& doc, const std::vector<uint32_t>& parent)
{
    const json* nodes = arrayMember(doc, "nodes");
    if (!nodes) return;
    if (nodes->size() > kMaxGltfNodes)
        failInFile(file, "the file has " + withThousands(nodes->size()) + " nodes; vkrt reads at most " +
                             withThousands(kMaxGltfNodes));
    const std::vector<uint64_t> times = importsPerNode(doc, *nodes, parent);
    const std::vector<uint64_t> triangles = meshTriangles(doc);
    // Every mesh a node names counts, in whichever scene: --scene may choose any.
    std::vector<bool> placed(triangles.size(), false);
    uint64_t importedNodes = 0, meshInstances = 0;
    for (uint32_t node = 0; node < nodes->size(); ++node) {
        importedNodes = saturatingAdd(importedNodes, times[node]);
        const auto mesh = uintMember((*nodes)[node], "mesh");
        if (!mesh || *mesh >= placed.size()) continue;
        placed[*mesh] = true;
        meshInstances = saturatingAdd(meshInstances, times[node]);
    }
    if (importedNodes > kMaxGltfNodes)
        failInFile(file, "the scene reaches " + withThousands(importedNodes) +
                             " nodes (a node listed more than once among its roots is reached each time, with its "
                             "children); vkrt reads at most " +
                             withThousands(kMaxGltfNodes));
    if (meshInstances > kMaxGltfInstances)
        failInFile(file, "the node hierarchy places meshes " + withThousands(meshInstances) +
                             " times; vkrt reads at most " + withThousands(kMaxGltfInstances) + " instances");
    uint64_t total = 0;
    size_t largest = 0;
    for (size_t m = 0; m < triangles.size(); ++m) {
        if (!placed[m]) continue;
        total = saturatingAdd(total, triangles[m]);
        if (triangles[m] > triangles[largest] || !placed[largest]) largest = m;
    }
    if (total > kMaxGltfTriangles)
        failInFile(file, "the meshes the scene places hold " + withThousands(total) + " triangles (mesh " +
                             std::to_string(largest) + ": " + withThousands(triangles[largest]) +
                             "); vkrt reads at most " + withThousands(kMaxGltfTriangles));
}

/// The bytes of accessor data one reference asks the reader for: count x
/// element size, twice without a bufferView (zeros made, then substituted).
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
        failInFile(file, "the meshes, morph targets, skins and animations use " + withThousands(bytes) +
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

json checkedGltfDocument(const fs::path& file, const ReferencePolicy& references)
{
    json doc = parseJson(file);
    checkGltfSchema(file, doc); // first: the checks below read wrongly typed fields as absent
    checkBufferBounds(file, doc);
    checkInstancing(file, doc, checkNodeHierarchy(file, doc));
    checkAccessorUse(file, doc);
    checkFileReferences(file, doc, references);
    return doc;
}

void checkGltfBeforeImport(const fs::path& file, const ReferencePolicy& references)
{
    checkedGltfDocument(file, references);
}

namespace {

/// A number of an extension object, checked to lie in [low, high], or `fallback`.
float extensionNumber(const fs::path& file, const json& extension, const char* extensionName, const char* key,
                      float fallback, float low, float high)
{
    const json* value = member(extension, key);
    if (!value) return fallback;
    if (!value->is_number() || !(value->get<double>() >= low && value->get<double>() <= high))
        failInFile(file, std::string(extensionName) + "." + key + ": must be a number in [" + std::to_string(low) +
                             ", " + std::to_string(high) + "]");
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
            !(std::abs((*value)[0].get<double>()) <= kMaxKernelMagnitude) ||
            !(std::abs((*value)[1].get<double>()) <= kMaxKernelMagnitude))
            failInFile(file, where + "." + key +
                                 ": expected two numbers of magnitude at most 1e18 (the kernel's float32 "
                                 "texture coordinates)");
        return glm::dvec2((*value)[0].get<double>(), (*value)[1].get<double>());
    };
    texture->offset = pair("offset", glm::dvec2(0.0));
    texture->scale = pair("scale", glm::dvec2(1.0));
    if (const json* rotation = member(*transform, "rotation")) {
        if (!rotation->is_number() || !std::isfinite(rotation->get<double>()))
            failInFile(file, where + ".rotation: expected a finite number");
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
    readTextureTransform(file, member(material, "emissiveTexture"), "emissiveTexture", out.emissiveTexture);
    const json* extensions = member(material, "extensions");
    if (!extensions) return;
    out.unlit = member(*extensions, "KHR_materials_unlit") != nullptr;
    if (const json* e = member(*extensions, "KHR_materials_emissive_strength"))
        out.emissiveFactor *= extensionNumber(file, *e, "KHR_materials_emissive_strength", "emissiveStrength", 1.0f,
                                              0.0f, std::numeric_limits<float>::max());
    if (const json* e = member(*extensions, "KHR_materials_transmission"))
        out.transmission =
            extensionNumber(file, *e, "KHR_materials_transmission", "transmissionFactor", 0.0f, 0.0f, 1.0f);
    if (const json* e = member(*extensions, "KHR_materials_ior")) {
        out.ior = extensionNumber(file, *e, "KHR_materials_ior", "ior", 1.5f, 0.0f, 1e30f);
        if (out.ior != 0.0f && out.ior < 1.0f)
            failInFile(file, "KHR_materials_ior.ior: must be 0 or at least 1, got " + std::to_string(out.ior));
        if (out.ior == 0.0f) out.ior = 1.5f; // glTF: 0 means the default dielectric; vkrt has no ideal metal here
    }
    if (!std::isfinite(out.emissiveFactor.r + out.emissiveFactor.g + out.emissiveFactor.b))
        failInFile(file, "emissiveFactor x KHR_materials_emissive_strength is beyond 32-bit float range");
}

} // namespace

namespace {

// ---------------------------------------------------------------------------
// A material's JSON -> FileMaterial, glTF 2.0's defaults for what it omits.

/// glTF sampler wrap modes (WebGL enums).
TextureWrap wrapMode(uint32_t mode)
{
    if (mode == 33071) return TextureWrap::Clamp;
    if (mode == 33648) return TextureWrap::Mirror;
    return TextureWrap::Repeat; // 10497, glTF's default
}

/// Each embedded image's bytes, read once per file and shared by every
/// texture slot that names the image (15,000 slots naming one 197 KB PNG
/// made 15,000 copies, 2.9 GB, before).
using EmbeddedImages = std::map<uint32_t, std::shared_ptr<const std::vector<uint8_t>>>;

struct MaterialReader {
    const json& doc;
    const fs::path& file;
    const ReferencePolicy& references;
    const GltfViewBytes& viewBytes;
    std::string materialName; ///< for messages
    EmbeddedImages& embeddedImages;

    [[noreturn]] void malformed(const std::string& what) const
    {
        failInFile(file, "material " + materialName + ": " + what);
    }

    float unitFactor(const json* owner, const char* key, float fallback) const
    {
        const json* value = owner ? member(*owner, key) : nullptr;
        if (!value) return fallback;
        if (!value->is_number() || !(value->get<double>() >= 0.0 && value->get<double>() <= 1.0))
            malformed(std::string(key) + " must be a number in [0, 1]");
        return float(value->get<double>());
    }

    /// A number of `owner` at least `low`, finite in 32-bit floats (`name` names it in messages).
    float numberAtLeast(const json& owner, const char* key, const char* name, float low, float fallback) const
    {
        const json* value = member(owner, key);
        if (!value) return fallback;
        if (!value->is_number() || !(value->get<double>() >= low) ||
            !(value->get<double>() <= std::numeric_limits<float>::max()))
            malformed(std::string(name) + "." + key + " must be a finite number >= " + std::to_string(low));
        return float(value->get<double>());
    }

    /// A finite number of `owner` (`name` names it in messages).
    float finiteNumber(const json& owner, const char* key, const char* name, float fallback) const
    {
        const json* value = member(owner, key);
        if (!value) return fallback;
        if (!value->is_number() || !(std::abs(value->get<double>()) <= std::numeric_limits<float>::max()))
            malformed(std::string(name) + "." + key + " must be a finite number");
        return float(value->get<double>());
    }

    glm::vec4 colour(const json* owner, const char* key, glm::vec4 fallback, size_t size, bool unbounded) const
    {
        const json* value = owner ? member(*owner, key) : nullptr;
        if (!value) return fallback;
        if (!value->is_array() || value->size() != size)
            malformed(std::string(key) + " must be an array of " + std::to_string(size) + " numbers");
        glm::vec4 out = fallback;
        for (size_t i = 0; i < size; ++i) {
            const json& c = (*value)[i];
            if (!c.is_number() || !std::isfinite(c.get<double>()) || c.get<double>() < 0.0 ||
                (!unbounded && c.get<double>() > 1.0) || c.get<double>() > std::numeric_limits<float>::max())
                malformed(std::string(key) + " has a component that is " +
                          (unbounded ? "negative or not finite" : "outside [0, 1]"));
            out[int(i)] = float(c.get<double>());
        }
        return out;
    }

    /// A sampler's magFilter and minFilter (glTF 2.0, 5.26); an absent one
    /// keeps vkrt's default, any other value than glTF's is an error.
    TextureFilter filterOf(const json& sampler, uint32_t index, const char* slot) const
    {
        TextureFilter filter;
        const std::string which = std::string(slot) + "'s sampler " + std::to_string(index) + ": ";
        if (const json* mag = member(sampler, "magFilter")) {
            const uint32_t code = uintMember(sampler, "magFilter").value_or(0);
            if (code != 9728 && code != 9729)
                malformed(which + "magFilter is " + mag->dump() + "; glTF allows 9728 (NEAREST) and 9729 (LINEAR)");
            filter.magNearest = code == 9728;
        }
        const json* min = member(sampler, "minFilter");
        if (!min) return filter;
        using Mip = TextureFilter::Mip;
        switch (uintMember(sampler, "minFilter").value_or(0)) {
        case 9728: filter.minNearest = true, filter.mip = Mip::None; break;    // NEAREST
        case 9729: filter.mip = Mip::None; break;                              // LINEAR
        case 9984: filter.minNearest = true, filter.mip = Mip::Nearest; break; // NEAREST_MIPMAP_NEAREST
        case 9985: filter.mip = Mip::Nearest; break;                           // LINEAR_MIPMAP_NEAREST
        case 9986: filter.minNearest = true; break;                            // NEAREST_MIPMAP_LINEAR
        case 9987: break;                                                      // LINEAR_MIPMAP_LINEAR
        default:
            malformed(which + "minFilter is " + min->dump() +
                      "; glTF allows 9728 (NEAREST), 9729 (LINEAR) and 9984 to 9987 (the MIPMAP filters)");
        }
        return filter;
    }

    /// The image of a texture: a file beside the glTF, or bytes inside it.
    void readImage(uint32_t index, FileTexture& texture) const
    {
        const json* image = element(arrayMember(doc, "images"), index);
        if (!image || !image->is_object())
            malformed("names image " + std::to_string(index) + ", which the file does not have");
        const json* uri = member(*image, "uri");
        if (uri && uri->is_string() && uri->get<std::string>().rfind("data:", 0) != 0) {
            const std::string text = uri->get<std::string>();
            texture.file = file.parent_path() / gltfUriPath(text);
            references.check(texture.file, text, "material " + materialName + "'s image");
            texture.name = texture.file.string();
            return;
        }
        texture.name = file.string() + " (embedded image " + std::to_string(index) + ")";
        std::shared_ptr<const std::vector<uint8_t>>& bytes = embeddedImages[index];
        if (!bytes) bytes = std::make_shared<const std::vector<uint8_t>>(embeddedBytes(*image, uri, index));
        texture.embedded = bytes;
    }

    /// An embedded image's bytes: a base64 data: URI's, or its bufferView's.
    std::vector<uint8_t> embeddedBytes(const json& image, const json* uri, uint32_t index) const
    {
        if (uri && uri->is_string()) {
            const std::string text = uri->get<std::string>();
            const size_t comma = text.find(',');
            if (comma == std::string::npos || comma < 7 || text.compare(comma - 7, 7, ";base64") != 0)
                malformed("image " + std::to_string(index) + "'s data: URI is not base64");
            std::vector<uint8_t> decoded = decodeBase64(std::string_view(text).substr(comma + 1));
            if (decoded.empty()) malformed("image " + std::to_string(index) + "'s base64 data is malformed");
            return decoded;
        }
        if (const auto view = uintMember(image, "bufferView"))
            return viewBytes(*view, "images[" + std::to_string(index) + "]");
        malformed("image " + std::to_string(index) + " has neither a uri nor a bufferView");
    }

    std::optional<FileTexture> texture(const json* info, const char* slot) const
    {
        if (!info) return std::nullopt;
        const auto index = uintMember(*info, "index");
        const json* entry = index ? element(arrayMember(doc, "textures"), *index) : nullptr;
        if (!entry || !entry->is_object()) malformed(std::string(slot) + " names a texture the file does not have");
        const auto source = uintMember(*entry, "source");
        if (!source) malformed(std::string(slot) + "'s texture has no source image vkrt can read (only PNG and JPEG)");
        FileTexture texture;
        readImage(*source, texture);
        if (const auto sampler = uintMember(*entry, "sampler")) {
            const json* s = element(arrayMember(doc, "samplers"), *sampler);
            if (!s) malformed(std::string(slot) + "'s texture names a sampler the file does not have");
            texture.wrapU = wrapMode(uintMember(*s, "wrapS").value_or(10497));
            texture.wrapV = wrapMode(uintMember(*s, "wrapT").value_or(10497));
            texture.filter = filterOf(*s, *sampler, slot);
        }
        texture.texCoord = uintMember(*info, "texCoord").value_or(0);
        const json* extensions = member(*info, "extensions");
        const json* transform = extensions ? member(*extensions, "KHR_texture_transform") : nullptr;
        if (transform)
            if (const auto texCoord = uintMember(*transform, "texCoord")) texture.texCoord = *texCoord;
        if (texture.texCoord > 1)
            malformed(std::string(slot) + " reads TEXCOORD_" + std::to_string(texture.texCoord) +
                      "; vkrt reads TEXCOORD_0 and TEXCOORD_1");
        return texture;
    }

    FileMaterial convert(const json& m) const
    {
        FileMaterial out;
        if (!m.is_object()) malformed("expected an object");
        if (const json* name = member(m, "name"); name && name->is_string()) out.name = name->get<std::string>();
        const json* pbr = member(m, "pbrMetallicRoughness");
        out.baseColorFactor = colour(pbr, "baseColorFactor", out.baseColorFactor, 4, false);
        out.baseColorTexture = texture(pbr ? member(*pbr, "baseColorTexture") : nullptr, "baseColorTexture");
        out.metallicFactor = unitFactor(pbr, "metallicFactor", out.metallicFactor);
        out.roughnessFactor = unitFactor(pbr, "roughnessFactor", out.roughnessFactor);
        out.metallicRoughnessTexture =
            texture(pbr ? member(*pbr, "metallicRoughnessTexture") : nullptr, "metallicRoughnessTexture");
        const json* normal = member(m, "normalTexture");
        out.normalTexture = texture(normal, "normalTexture");
        if (const json* scale = normal ? member(*normal, "scale") : nullptr) {
            // The kernel scales the map's X and Y in float32: 1e39 became infinite there (no normal map at all).
            if (!scale->is_number() || !(std::abs(scale->get<double>()) <= kMaxKernelMagnitude))
                malformed("normalTexture.scale must be a number of magnitude at most 1e18");
            out.normalScale = float(scale->get<double>());
        }
        out.emissiveFactor = glm::vec3(colour(&m, "emissiveFactor", glm::vec4(0.0f), 3, true));
        out.emissiveTexture = texture(member(m, "emissiveTexture"), "emissiveTexture");
        const std::string mode =
            member(m, "alphaMode") && m["alphaMode"].is_string() ? m["alphaMode"].get<std::string>() : "OPAQUE";
        if (mode == "MASK") out.alphaMode = AlphaMode::Mask;
        else if (mode == "BLEND") out.alphaMode = AlphaMode::Blend;
        else if (mode != "OPAQUE") malformed("alphaMode must be OPAQUE, MASK or BLEND, not '" + mode + "'");
        if (const json* cutoff = member(m, "alphaCutoff")) {
            if (!cutoff->is_number() || !(cutoff->get<double>() >= 0.0) || !std::isfinite(cutoff->get<double>()))
                malformed("alphaCutoff must be a finite number >= 0");
            out.alphaCutoff = float(cutoff->get<double>());
        }
        if (const json* two = member(m, "doubleSided"); two && two->is_boolean()) out.doubleSided = two->get<bool>();
        if (const json* extensions = member(m, "extensions")) readLayers(*extensions, out);
        return out;
    }

    /// The texture `key` of extension object `e`, with its KHR_texture_transform.
    std::optional<FileTexture> layerTexture(const json& e, const char* key) const
    {
        std::optional<FileTexture> t = texture(member(e, key), key);
        readTextureTransform(file, member(e, key), key, t);
        return t;
    }

    /// KHR_materials_specular, _sheen, _volume and _clearcoat: their factors and textures.
    void readLayers(const json& extensions, FileMaterial& out) const
    {
        if (const json* e = member(extensions, "KHR_materials_specular")) {
            out.specularFactor = unitFactor(e, "specularFactor", out.specularFactor);
            out.specularTexture = layerTexture(*e, "specularTexture");
            out.specularColorFactor = glm::vec3(colour(e, "specularColorFactor", glm::vec4(1.0f), 3, true));
            out.specularColorTexture = layerTexture(*e, "specularColorTexture");
        }
        if (const json* e = member(extensions, "KHR_materials_sheen")) {
            out.sheenColorFactor = glm::vec3(colour(e, "sheenColorFactor", glm::vec4(0.0f), 3, false));
            out.sheenColorTexture = layerTexture(*e, "sheenColorTexture");
            out.sheenRoughnessFactor = unitFactor(e, "sheenRoughnessFactor", out.sheenRoughnessFactor);
            out.sheenRoughnessTexture = layerTexture(*e, "sheenRoughnessTexture");
        }
        if (const json* e = member(extensions, "KHR_materials_volume")) {
            if (const json* t = member(*e, "thicknessFactor")) {
                if (!t->is_number() || !(t->get<double>() >= 0.0) || !std::isfinite(t->get<double>()))
                    malformed("KHR_materials_volume.thicknessFactor must be a finite number >= 0");
                out.thicknessFactor = float(t->get<double>());
            }
            if (const json* d = member(*e, "attenuationDistance")) {
                if (!d->is_number() || !(d->get<double>() > 0.0))
                    malformed("KHR_materials_volume.attenuationDistance must be a number > 0");
                out.attenuationDistance = float(std::min(d->get<double>(), double(std::numeric_limits<float>::max())));
            }
            out.attenuationColor = glm::vec3(colour(e, "attenuationColor", glm::vec4(1.0f), 3, false));
        }
        if (const json* e = member(extensions, "KHR_materials_transmission"))
            out.transmissionTexture = layerTexture(*e, "transmissionTexture");
        if (const json* e = member(extensions, "KHR_materials_iridescence")) {
            out.iridescenceFactor = unitFactor(e, "iridescenceFactor", out.iridescenceFactor);
            out.iridescenceTexture = layerTexture(*e, "iridescenceTexture");
            const char* name = "KHR_materials_iridescence";
            out.iridescenceIor = numberAtLeast(*e, "iridescenceIor", name, 1.0f, out.iridescenceIor);
            out.iridescenceThicknessMinimum =
                numberAtLeast(*e, "iridescenceThicknessMinimum", name, 0.0f, out.iridescenceThicknessMinimum);
            out.iridescenceThicknessMaximum =
                numberAtLeast(*e, "iridescenceThicknessMaximum", name, 0.0f, out.iridescenceThicknessMaximum);
            out.iridescenceThicknessTexture = layerTexture(*e, "iridescenceThicknessTexture");
        }
        if (const json* e = member(extensions, "KHR_materials_clearcoat")) {
            out.clearcoatFactor = unitFactor(e, "clearcoatFactor", out.clearcoatFactor);
            out.clearcoatTexture = layerTexture(*e, "clearcoatTexture");
            out.clearcoatRoughnessFactor = unitFactor(e, "clearcoatRoughnessFactor", out.clearcoatRoughnessFactor);
            out.clearcoatRoughnessTexture = layerTexture(*e, "clearcoatRoughnessTexture");
            out.clearcoatNormalTexture = layerTexture(*e, "clearcoatNormalTexture");
            if (const json* normal = member(*e, "clearcoatNormalTexture")) {
                out.clearcoatNormalScale = finiteNumber(*normal, "scale", "clearcoatNormalTexture", 1.0f);
                if (!(std::abs(out.clearcoatNormalScale) <= kMaxKernelMagnitude))
                    malformed("clearcoatNormalTexture.scale must be a number of magnitude at most 1e18");
            }
        }
        if (const json* e = member(extensions, "KHR_materials_anisotropy")) {
            out.anisotropyStrength = unitFactor(e, "anisotropyStrength", out.anisotropyStrength);
            out.anisotropyRotation = finiteNumber(*e, "anisotropyRotation", "KHR_materials_anisotropy", 0.0f);
            out.anisotropyTexture = layerTexture(*e, "anisotropyTexture");
        }
    }
};

std::string describeMaterial(size_t index, const json& material)
{
    const json* name = member(material, "name");
    return std::to_string(index) + (name && name->is_string() ? " '" + name->get<std::string>() + "'" : "");
}

} // namespace

std::vector<const std::optional<FileTexture>*> FileMaterial::textureSlots() const
{
    return {&baseColorTexture,   &metallicRoughnessTexture,    &normalTexture,          &emissiveTexture,
            &specularTexture,    &specularColorTexture,        &sheenColorTexture,      &sheenRoughnessTexture,
            &clearcoatTexture,   &clearcoatRoughnessTexture,   &clearcoatNormalTexture, &transmissionTexture,
            &iridescenceTexture, &iridescenceThicknessTexture, &anisotropyTexture};
}

std::vector<uint8_t> decodeBase64(std::string_view text)
{
    auto value = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        if (c == '+' || c == '-') return 62;
        if (c == '/' || c == '_') return 63;
        return -1;
    };
    std::vector<uint8_t> out;
    out.reserve(text.size() / 4 * 3);
    uint32_t bits = 0;
    int count = 0;
    for (char c : text) {
        if (c == '=') break;
        const int v = value(c);
        if (v < 0) return {};
        bits = (bits << 6) | uint32_t(v);
        if (++count == 4) {
            out.insert(out.end(), {uint8_t(bits >> 16), uint8_t(bits >> 8), uint8_t(bits)});
            bits = 0;
            count = 0;
        }
    }
    if (count == 1) return {};
    if (count == 2) out.push_back(uint8_t(bits >> 4));
    if (count == 3) out.insert(out.end(), {uint8_t(bits >> 10), uint8_t(bits >> 2)});
    return out;
}

fs::path gltfUriPath(const std::string& uri) { return fs::path(percentDecoded(uri)); }

std::vector<FileMaterial> readGltfMaterials(const json& doc, const fs::path& file, const ReferencePolicy& references,
                                            const GltfViewBytes& viewBytes)
{
    std::vector<FileMaterial> materials;
    EmbeddedImages embeddedImages;
    if (const json* list = arrayMember(doc, "materials")) {
        for (size_t i = 0; i < list->size(); ++i) {
            const json& source = (*list)[i];
            const MaterialReader reader{doc, file, references, viewBytes, describeMaterial(i, source), embeddedImages};
            FileMaterial material = reader.convert(source);
            material.fileIndex = int(i);
            material.unsupported = materialProblems(source);
            readHonouredExtensions(file, source, material);
            materials.push_back(std::move(material));
        }
    }
    materials.emplace_back(); // glTF's default material, for primitives without one
    return materials;
}

} // namespace vkrt
