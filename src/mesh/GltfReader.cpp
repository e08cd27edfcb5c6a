// glTF 2.0 files read once (mesh/GltfReader.h): buffers, accessors,
// primitives, the node tree and the materials, from the JSON document that
// checkGltfDocument has checked. Every read of the buffers is bounds-checked
// here again against the bytes actually loaded, so nothing below trusts the
// JSON's byte counts.
#include "mesh/GltfReader.h"

#include "mesh/FileMaterials.h"
#include "mesh/GltfJson.h"
#include "util/Error.h"
#include "util/KernelLimits.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <unordered_set>

namespace vkrt {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace gltf_json;

std::string indexed(const char* array, uint64_t index)
{
    return std::string(array) + "[" + std::to_string(index) + "]";
}

// ------------------------------------------------------------------ buffers

/// The bytes of a file the glTF needs (itself, a buffer), at most 2 GiB.
std::string readBytes(const fs::path& path)
{
    std::error_code error;
    if (fs::is_directory(path, error)) throw InputError(path.string() + ": is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": no such file, or it cannot be opened");
    const uint64_t size = fs::file_size(path, error);
    constexpr uint64_t kMaxBytes = uint64_t(1) << 31;
    if (error || size > kMaxBytes)
        throw InputError(path.string() + ": larger than the 2 GiB vkrt reads of a glTF file or buffer");
    std::string bytes(size_t(size), '\0');
    if (!in.read(bytes.data(), std::streamsize(size))) throw InputError(path.string() + ": cannot be read");
    return bytes;
}

constexpr uint32_t kGlbMagic = 0x46546C67;     // "glTF"
constexpr uint32_t kGlbJsonChunk = 0x4E4F534A; // "JSON"
constexpr uint32_t kGlbBinChunk = 0x004E4942;  // "BIN\0"

uint32_t word(const std::string& bytes, size_t offset)
{
    uint32_t value = 0;
    if (offset + 4 <= bytes.size()) std::memcpy(&value, bytes.data() + offset, 4);
    return value;
}

/// A .glb's BIN chunk (the one after the JSON chunk), or nullopt for a .gltf
/// or a .glb without one.
std::optional<std::string> glbBinaryChunk(const fs::path& file)
{
    const std::string bytes = readBytes(file);
    if (word(bytes, 0) != kGlbMagic) return std::nullopt;
    const uint64_t jsonLength = word(bytes, 12);
    if (word(bytes, 16) != kGlbJsonChunk) failInFile(file, "the binary glTF's first chunk is not JSON");
    const uint64_t next = 20 + jsonLength;
    if (next + 8 > bytes.size()) return std::nullopt;
    const uint64_t length = word(bytes, size_t(next));
    if (word(bytes, size_t(next) + 4) != kGlbBinChunk) return std::nullopt;
    if (next + 8 + length > bytes.size())
        failInFile(file, "the binary glTF's BIN chunk says " + std::to_string(length) +
                             " bytes, but the file ends after " + std::to_string(bytes.size() - next - 8));
    return bytes.substr(size_t(next) + 8, size_t(length));
}

/// The bytes of a `data:` URI (base64; RFC 2397), or nullopt when it is not one vkrt can decode.
std::optional<std::string> dataUriBytes(const std::string& uri)
{
    const size_t comma = uri.find(',');
    if (comma == std::string::npos || comma < 7 || uri.compare(comma - 7, 7, ";base64") != 0) return std::nullopt;
    const std::vector<uint8_t> bytes = decodeBase64(std::string_view(uri).substr(comma + 1));
    if (bytes.empty() && comma + 1 < uri.size()) return std::nullopt;
    return std::string(bytes.begin(), bytes.end());
}

/// The document and its buffers' bytes.
struct Document {
    fs::path file;
    json doc;
    ReferencePolicy references;
    std::vector<std::string> buffers;
    std::vector<fs::path> bufferFiles; ///< the buffers read from files

    const json* array(const char* key) const { return arrayMember(doc, key); }

    const json& element(const char* key, uint64_t index, const std::string& where) const
    {
        const json* list = array(key);
        if (!list || index >= list->size() || !(*list)[index].is_object())
            failInFile(file, where + " names " + indexed(key, index) + ", which the file does not have");
        return (*list)[index];
    }

    /// `length` bytes at `offset` of bufferView `view`, checked against the loaded buffer.
    const char* viewBytes(uint64_t view, uint64_t offset, uint64_t length, const std::string& where) const
    {
        const json& v = element("bufferViews", view, where);
        const auto buffer = uintMember(v, "buffer");
        if (!buffer || *buffer >= buffers.size()) failInFile(file, indexed("bufferViews", view) + ": no such buffer");
        const uint64_t viewOffset = uintMember(v, "byteOffset").value_or(0);
        const uint64_t viewLength = uintMember(v, "byteLength").value_or(0);
        const std::string& bytes = buffers[*buffer];
        if (offset > viewLength || length > viewLength - offset || viewOffset > bytes.size() ||
            viewOffset + viewLength > bytes.size())
            failInFile(file, where + " reads bytes " + std::to_string(offset) + " to " +
                                 std::to_string(offset + length) + " of " + indexed("bufferViews", view) + " (" +
                                 std::to_string(viewLength) + " bytes), beyond its buffer's data");
        return bytes.data() + viewOffset + offset;
    }
};

std::string loadBuffer(Document& d, size_t index, const std::optional<std::string>& glbChunk)
{
    const json& buffer = (*d.array("buffers"))[index];
    const std::string where = indexed("buffers", index);
    const auto length = member(buffer, "byteLength") ? uintMember(buffer, "byteLength") : std::nullopt;
    if (!length) failInFile(d.file, where + ": byteLength must be an integer from 1 to 2^32 - 1");
    std::string bytes;
    const std::string uri = stringMember(buffer, "uri");
    if (!member(buffer, "uri")) {
        if (index != 0 || !glbChunk) failInFile(d.file, where + " has no uri and is not a binary glTF's BIN chunk");
        bytes = *glbChunk;
    } else if (uri.rfind("data:", 0) == 0) {
        const auto decoded = dataUriBytes(uri);
        if (!decoded) failInFile(d.file, where + ": its data: URI is not base64 data vkrt can decode");
        bytes = *decoded;
    } else {
        const fs::path path = d.file.parent_path() / gltfUriPath(uri);
        d.references.check(path, uri, "buffer " + std::to_string(index));
        try {
            bytes = readBytes(path);
            d.bufferFiles.push_back(path);
        } catch (const InputError& error) {
            failInFile(d.file, "the referenced file '" + uri + "' cannot be read: " + error.what());
        }
    }
    if (bytes.size() < *length)
        failInFile(d.file, where + " holds " + std::to_string(bytes.size()) + " bytes, but its byteLength is " +
                               std::to_string(*length));
    bytes.resize(*length);
    return bytes;
}

Document openDocument(const fs::path& file, const MeshLoadOptions& options)
{
    Document d{file, checkedGltfDocument(file, ReferencePolicy(file, options)), ReferencePolicy(file, options), {}};
    const std::string version = member(d.doc, "asset") ? stringMember(d.doc["asset"], "version") : "";
    if (version.rfind("2.", 0) != 0)
        failInFile(file, "asset.version is " + (version.empty() ? std::string("missing") : "'" + version + "'") +
                             ": vkrt reads glTF 2.0");
    if (const json* buffers = d.array("buffers")) {
        const std::optional<std::string> chunk = glbBinaryChunk(file);
        for (size_t i = 0; i < buffers->size(); ++i) d.buffers.push_back(loadBuffer(d, i, chunk));
    }
    return d;
}

// ---------------------------------------------------------------- accessors

struct ElementType {
    uint32_t components = 0;
    uint32_t componentType = 0;
    bool normalized = false;
};

/// One component as a double: floats as they are, integers as integers or,
/// normalized, as glTF's normalization says (signed: max(c / max, -1)).
double componentValue(const char* at, const ElementType& type)
{
    switch (type.componentType) {
    case 5120: {
        int8_t v;
        std::memcpy(&v, at, 1);
        return type.normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case 5121: {
        uint8_t v;
        std::memcpy(&v, at, 1);
        return type.normalized ? v / 255.0 : v;
    }
    case 5122: {
        int16_t v;
        std::memcpy(&v, at, 2);
        return type.normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case 5123: {
        uint16_t v;
        std::memcpy(&v, at, 2);
        return type.normalized ? v / 65535.0 : v;
    }
    case 5125: {
        uint32_t v;
        std::memcpy(&v, at, 4);
        return type.normalized ? v / 4294967295.0 : v;
    }
    default: {
        float v;
        std::memcpy(&v, at, 4);
        return v;
    }
    }
}

/// Reads elements of an accessor (or a sparse part) from a view: count x
/// components values. T is float for attributes (exact for every 8- and
/// 16-bit integer and every float), uint32_t for indices (unsigned types only).
template <class T>
void readElements(const Document& d, uint64_t view, uint64_t offset, uint64_t count, const ElementType& type,
                  uint64_t stride, const std::string& where, T* out)
{
    if (stride > 252) // glTF's bound; it keeps (count - 1) * stride far from overflow
        failInFile(d.file, where + ": its bufferView's byteStride " + std::to_string(stride) + " is over glTF's 252");
    const uint64_t size = uint64_t(componentBytes(type.componentType)) * type.components;
    if (count == 0) return;
    const char* bytes = d.viewBytes(view, offset, (count - 1) * stride + size, where);
    for (uint64_t i = 0; i < count; ++i)
        for (uint32_t c = 0; c < type.components; ++c)
            out[i * type.components + c] =
                T(componentValue(bytes + i * stride + c * componentBytes(type.componentType), type));
}

template <class T = float>
struct Accessor {
    uint64_t count = 0;
    uint32_t components = 0;
    std::vector<T> values; ///< count x components
    double at(uint64_t i, uint32_t c) const { return double(values[i * components + c]); }
};

/// The most values (elements x components) one accessor may hold here: 2 GiB
/// of floats, beyond the 8 Mi-triangle soup kMaxGltfTriangles allows (75 M).
constexpr uint64_t kMaxAccessorValues = uint64_t(1) << 27;

uint32_t componentsOf(const std::string& type)
{
    if (type == "SCALAR") return 1;
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4") return 4;
    return 0;
}

/// glTF 2.0, 3.6.2.4: an accessor's offset into its bufferView and into its
/// buffer, and its bufferView's stride, are multiples of its component size.
void checkAlignment(const Document& d, const json& accessor, const json& view, uint64_t viewIndex,
                    uint32_t componentSize, const std::string& name)
{
    const uint64_t offset = uintMember(accessor, "byteOffset").value_or(0);
    const uint64_t viewOffset = uintMember(view, "byteOffset").value_or(0);
    const uint64_t stride = uintMember(view, "byteStride").value_or(0);
    if (offset % componentSize != 0 || (offset + viewOffset) % componentSize != 0 || stride % componentSize != 0)
        failInFile(d.file, name + ": its byteOffset (" + std::to_string(offset) + "), its place in its buffer (" +
                               std::to_string(offset + viewOffset) + ") and " + indexed("bufferViews", viewIndex) +
                               "'s byteStride (" + std::to_string(stride) + ") must be multiples of its " +
                               std::to_string(componentSize) + "-byte components");
}

/// Accessor `index`, of one of the `allowed` element sizes, sparse substitution applied.
template <class T = float>
Accessor<T> readAccessor(const Document& d, uint64_t index, std::initializer_list<uint32_t> allowed,
                         const std::string& where)
{
    const std::string name = indexed("accessors", index);
    const json& a = d.element("accessors", index, where);
    ElementType type;
    type.components = componentsOf(stringMember(a, "type"));
    type.componentType = uintMember(a, "componentType").value_or(0);
    type.normalized = member(a, "normalized") && a["normalized"].is_boolean() && a["normalized"].get<bool>();
    if (std::find(allowed.begin(), allowed.end(), type.components) == allowed.end())
        failInFile(d.file, where + " uses " + name + " of type '" + stringMember(a, "type") + "', which it cannot be");
    const uint32_t size = componentBytes(type.componentType);
    if (size == 0) failInFile(d.file, name + ": unknown componentType");
    const auto count = uintMember(a, "count");
    if (!count || *count == 0) failInFile(d.file, name + ": count must be at least 1");
    if (uint64_t(*count) * type.components > kMaxAccessorValues)
        failInFile(d.file, name + ": " + std::to_string(*count) + " elements; vkrt reads at most " +
                               std::to_string(kMaxAccessorValues / type.components) + " of this type");
    Accessor<T> out;
    out.count = *count;
    out.components = type.components;
    out.values.assign(size_t(*count) * type.components, T(0)); // no bufferView: zeros (then the sparse values)
    if (const auto view = uintMember(a, "bufferView")) {
        const json& v = d.element("bufferViews", *view, name);
        const uint64_t stride = uintMember(v, "byteStride").value_or(0);
        const uint64_t element = uint64_t(size) * type.components;
        const uint64_t offset = uintMember(a, "byteOffset").value_or(0);
        checkAlignment(d, a, v, *view, size, name);
        // glTF 2.0, 3.6.2.4: elements may interleave, never overlap.
        if (stride != 0 && stride < element)
            failInFile(d.file, name + ": its bufferView's byteStride " + std::to_string(stride) +
                                   " is less than its elements' " + std::to_string(element) +
                                   " bytes (they would overlap)");
        readElements(d, *view, offset, *count, type, stride ? stride : element, name, out.values.data());
    }
    const json* sparse = member(a, "sparse");
    if (!sparse) return out;
    const std::string sparseName = name + ".sparse";
    const auto sparseCount = uintMember(*sparse, "count");
    const json* indices = member(*sparse, "indices");
    const json* values = member(*sparse, "values");
    if (!sparseCount || *sparseCount == 0 || *sparseCount > *count || !indices || !values)
        failInFile(d.file, sparseName + ": needs a count from 1 to the accessor's count, indices and values");
    ElementType indexType{1, uintMember(*indices, "componentType").value_or(0), false};
    if (indexType.componentType != 5121 && indexType.componentType != 5123 && indexType.componentType != 5125)
        failInFile(d.file, sparseName + ".indices: componentType must be an unsigned byte, short or int");
    const auto indexView = uintMember(*indices, "bufferView");
    const auto valueView = uintMember(*values, "bufferView");
    if (!indexView || !valueView) failInFile(d.file, sparseName + ": indices and values need a bufferView");
    std::vector<uint32_t> where_(*sparseCount);
    std::vector<T> substitutes(size_t(*sparseCount) * type.components);
    readElements(d, *indexView, uintMember(*indices, "byteOffset").value_or(0), *sparseCount, indexType,
                 componentBytes(indexType.componentType), sparseName + ".indices", where_.data());
    readElements(d, *valueView, uintMember(*values, "byteOffset").value_or(0), *sparseCount, type,
                 uint64_t(size) * type.components, sparseName + ".values", substitutes.data());
    for (uint64_t i = 0; i < *sparseCount; ++i) {
        const uint64_t target = where_[i];
        // glTF 2.0, 3.6.2.3: "the indices MUST strictly increase" (each element substituted once, in order).
        if (i > 0 && target <= where_[i - 1])
            failInFile(d.file, sparseName + ".indices[" + std::to_string(i) + "] is " + std::to_string(target) +
                                   ", not above the index before it (" + std::to_string(where_[i - 1]) +
                                   "): sparse indices must strictly increase");
        if (target >= *count)
            failInFile(d.file, sparseName + ".indices[" + std::to_string(i) + "] is " + std::to_string(target) +
                                   ", beyond the accessor's " + std::to_string(*count) + " elements");
        std::copy_n(substitutes.begin() + long(i * type.components), type.components,
                    out.values.begin() + long(target * type.components));
    }
    return out;
}

// --------------------------------------------------------------- primitives

enum : uint32_t { kPoints = 0, kLines = 1, kLineLoop = 2, kLineStrip = 3, kTriangles = 4, kStrip = 5, kFan = 6 };

/// The triangles of a primitive's vertex sequence (glTF 2.0, 3.7.2.1).
std::vector<glm::uvec3> assembleTriangles(const std::vector<uint32_t>& v, uint32_t mode)
{
    std::vector<glm::uvec3> triangles;
    if (mode == kTriangles)
        for (size_t i = 0; i + 2 < v.size(); i += 3) triangles.push_back({v[i], v[i + 1], v[i + 2]});
    if (mode == kStrip)
        for (size_t i = 0; i + 2 < v.size(); ++i) triangles.push_back({v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]});
    if (mode == kFan)
        for (size_t i = 1; i + 1 < v.size(); ++i) triangles.push_back({v[i], v[i + 1], v[0]});
    return triangles;
}

/// The texture coordinate sets a material's textures read.
std::set<uint32_t> texCoordSets(const FileMaterial& m)
{
    std::set<uint32_t> sets;
    for (const std::optional<FileTexture>* t : m.textureSlots())
        if (*t) sets.insert((*t)->texCoord);
    return sets;
}

/// The material a primitive uses: its KHR_materials_variants mapping's for
/// the chosen variant, else its own `material`, else glTF's default (last).
uint32_t primitiveMaterial(const Document& d, const json& primitive, size_t materialCount,
                           std::optional<uint32_t> variant, const std::string& where)
{
    const auto own = uintMember(primitive, "material");
    if (member(primitive, "material") && (!own || *own + 1 >= materialCount))
        failInFile(d.file, where + ".material names a material the file does not have");
    uint32_t chosen = own.value_or(uint32_t(materialCount - 1));
    const json* extensions = member(primitive, "extensions");
    const json* variants = extensions ? member(*extensions, "KHR_materials_variants") : nullptr;
    const json* mappings = variants ? arrayMember(*variants, "mappings") : nullptr;
    if (!variant || !mappings) return chosen;
    for (const json& mapping : *mappings)
        if (const json* names = arrayMember(mapping, "variants"))
            for (const json& v : *names)
                if (v.is_number_unsigned() && v.get<uint64_t>() == *variant) {
                    const auto material = uintMember(mapping, "material");
                    if (!material || *material + 1 >= materialCount)
                        failInFile(d.file, where + ".extensions.KHR_materials_variants: a mapping names a material the "
                                                   "file does not have");
                    chosen = *material;
                }
    return chosen;
}

struct MeshBuilder {
    const Document& d;
    const std::vector<FileMaterial>& materials;
    std::vector<std::string>& warnings;
    std::optional<uint32_t> variant; ///< KHR_materials_variants' chosen variant
    MeshData out;
    bool anyNormals = false, anyUvs = false, anyUvs1 = false, anyColors = false, allTangents = true;
    std::optional<uint32_t> normalMapSet; ///< the uv set of the first normal map its primitives' materials have

    void warnOnce(const std::string& text)
    {
        if (std::find(warnings.begin(), warnings.end(), text) == warnings.end()) warnings.push_back(text);
    }

    static bool finite(const Accessor<>& a, uint64_t i)
    {
        for (uint32_t c = 0; c < a.components; ++c)
            if (!std::isfinite(a.at(i, c))) return false;
        return true;
    }

    void checkCount(const Accessor<>& a, uint64_t count, const std::string& where, const char* name) const
    {
        if (a.count != count)
            failInFile(d.file, where + ": " + name + " has " + std::to_string(a.count) + " elements, POSITION " +
                                   std::to_string(count));
    }

    /// A primitive's TEXCOORD_n attribute; a set its material's textures read must be there.
    std::optional<Accessor<>> uvSet(uint32_t set, const FileMaterial& material,
                                    const std::function<std::optional<Accessor<>>(const char*)>& optional,
                                    const std::string& where)
    {
        const std::string name = "TEXCOORD_" + std::to_string(set);
        std::optional<Accessor<>> uvs = optional(name.c_str());
        if (!uvs && texCoordSets(material).count(set))
            failInFile(d.file, where + ": its material (" +
                                   (material.name.empty() ? "unnamed" : "'" + material.name + "'") +
                                   ") samples textures through " + name + ", which the primitive does not have");
        return uvs;
    }

    /// Notes which uv set the primitive's normal map reads: the mesh's tangents follow it (glTF 3.7.2.1).
    void noteNormalMapSet(const FileMaterial& material, const std::string& where)
    {
        if (!material.normalTexture) return;
        const uint32_t set = material.normalTexture->texCoord;
        if (normalMapSet && *normalMapSet != set)
            warnOnce(where +
                     ": the mesh's normal maps read both TEXCOORD_0 and TEXCOORD_1; its tangents follow "
                     "TEXCOORD_" +
                     std::to_string(*normalMapSet));
        if (!normalMapSet) normalMapSet = set;
    }

    /// Appends one vertex's uv of `uvs` (zero without), v turned up (MeshData.h).
    void appendUv(std::vector<glm::vec2>& to, const std::optional<Accessor<>>& uvs, uint64_t i,
                  const std::string& where)
    {
        glm::vec2 uv(0.0f);
        if (uvs) {
            if (!finite(*uvs, i))
                failInFile(d.file, where + ": vertex " + std::to_string(i) + " has a non-finite texture coordinate");
            uv = glm::vec2(float(uvs->at(i, 0)), float(1.0 - uvs->at(i, 1)));
        }
        to.push_back(uv);
    }

    void addPrimitive(const json& primitive, const std::string& where)
    {
        const uint32_t mode = uintMember(primitive, "mode").value_or(kTriangles);
        if (mode > kFan) failInFile(d.file, where + ".mode: " + std::to_string(mode) + " is not a glTF primitive mode");
        if (mode < kTriangles) {
            warnOnce("points and lines (primitive modes 0-3) are not rendered");
            return;
        }
        const json* attributes = member(primitive, "attributes");
        const auto position = attributes ? uintMember(*attributes, "POSITION") : std::nullopt;
        if (!position) failInFile(d.file, where + ": a triangle primitive needs a POSITION attribute");
        const Accessor<> positions = readAccessor(d, *position, {3}, where + ".attributes.POSITION");
        const uint64_t count = positions.count;
        const uint32_t materialIndex = primitiveMaterial(d, primitive, materials.size(), variant, where);
        const FileMaterial& material = materials[materialIndex];
        auto optional = [&](const char* name, std::initializer_list<uint32_t> sizes) -> std::optional<Accessor<>> {
            const auto index = uintMember(*attributes, name);
            if (!index) return std::nullopt;
            Accessor<> a = readAccessor(d, *index, sizes, where + ".attributes." + name);
            checkCount(a, count, where, name);
            return a;
        };
        auto optionalUv = [&](const char* name) { return optional(name, {2}); };
        const std::optional<Accessor<>> normals = optional("NORMAL", {3});
        const std::optional<Accessor<>> tangents = normals ? optional("TANGENT", {4}) : std::nullopt;
        const std::optional<Accessor<>> uvs = uvSet(0, material, optionalUv, where);
        // TEXCOORD_1 is read only where a texture reads it: most files' second set is a lightmap's.
        const std::optional<Accessor<>> uvs1 =
            texCoordSets(material).count(1) ? uvSet(1, material, optionalUv, where) : std::nullopt;
        const std::optional<Accessor<>> colors = optional("COLOR_0", {3, 4});
        noteNormalMapSet(material, where);
        std::vector<uint32_t> sequence(count);
        if (const auto indices = uintMember(primitive, "indices")) {
            const std::string indicesWhere = where + ".indices";
            const json& indexAccessor = d.element("accessors", *indices, indicesWhere);
            const uint32_t type = uintMember(indexAccessor, "componentType").value_or(0);
            const json* normalized = member(indexAccessor, "normalized");
            if ((type != 5121 && type != 5123 && type != 5125) || (normalized && *normalized == true))
                failInFile(d.file, where + ".indices: accessor " + std::to_string(*indices) +
                                       " must hold unsigned bytes, shorts or ints, not normalized");
            const Accessor<uint32_t> a = readAccessor<uint32_t>(d, *indices, {1}, where + ".indices");
            sequence.resize(a.count);
            for (uint64_t i = 0; i < a.count; ++i) {
                if (a.values[i] >= count)
                    failInFile(d.file, where + ".indices[" + std::to_string(i) + "] is " + std::to_string(a.values[i]) +
                                           ", beyond the " + std::to_string(count) + " vertices");
                sequence[i] = a.values[i];
            }
        } else {
            for (uint32_t i = 0; i < count; ++i) sequence[i] = i;
        }
        // glTF 3.7.2.1: TRIANGLES' vertex count is a multiple of 3; a stray
        // index or two would otherwise be dropped without a word.
        if (mode == kTriangles && sequence.size() % 3 != 0)
            failInFile(d.file, where + ": a TRIANGLES primitive of " + std::to_string(sequence.size()) + " " +
                                   (member(primitive, "indices") ? "indices" : "vertices") + ", not a multiple of 3");
        if (out.positions.size() + count > UINT32_MAX) failInFile(d.file, "a mesh has more than 2^32 vertices");
        const auto base = uint32_t(out.positions.size());
        for (uint64_t i = 0; i < count; ++i) {
            if (!finite(positions, i))
                failInFile(d.file, where + ": vertex " + std::to_string(i) + " has a non-finite position");
            out.positions.emplace_back(positions.at(i, 0), positions.at(i, 1), positions.at(i, 2));
            glm::vec3 n(0.0f);
            if (normals) {
                if (!finite(*normals, i))
                    failInFile(d.file, where + ": vertex " + std::to_string(i) + " has a non-finite normal");
                const glm::dvec3 v(normals->at(i, 0), normals->at(i, 1), normals->at(i, 2));
                const double length = glm::length(v);
                if (length > 0.0) n = glm::vec3(v / length);
            }
            out.normals.push_back(n);
            glm::vec4 t(0.0f);
            if (tangents) {
                if (!finite(*tangents, i))
                    failInFile(d.file, where + ": vertex " + std::to_string(i) + " has a non-finite tangent");
                const glm::dvec3 v(tangents->at(i, 0), tangents->at(i, 1), tangents->at(i, 2));
                const double length = glm::length(v);
                // glTF's bitangent w cross(n, t) runs along decreasing file v (MikkTSpace's
                // increasing v before the exporter turned v down; the Khronos viewer's
                // computed b = cross(n, t) runs the same way), which is MeshData's
                // increasing v = 1 - file v: the sign carries over as it is. Read
                // inverted, a 45-degree anisotropy and a normal map's green turned the wrong way.
                const float w = tangents->at(i, 3) < 0.0 ? -1.0f : 1.0f;
                t = length > 0.0 ? glm::vec4(glm::vec3(v / length), w) : glm::vec4(0.0f);
            }
            out.tangents.push_back(t);
            appendUv(out.uvs, uvs, i, where);
            appendUv(out.uvs1, uvs1, i, where);
            glm::vec4 color(1.0f);
            if (colors) {
                if (!finite(*colors, i))
                    failInFile(d.file, where + ": vertex " + std::to_string(i) + " has a non-finite colour");
                for (uint32_t c = 0; c < colors->components; ++c) color[int(c)] = float(colors->at(i, c));
            }
            out.colors.push_back(color);
        }
        anyNormals |= normals.has_value();
        anyUvs |= uvs.has_value();
        anyUvs1 |= uvs1.has_value();
        anyColors |= colors.has_value();
        allTangents &= tangents.has_value();
        for (const glm::uvec3& t : assembleTriangles(sequence, mode)) {
            out.triangles.push_back(t + base);
            out.triangleMaterials.push_back(materialIndex);
        }
    }

    /// Drops the attributes no primitive had; tangents unless every primitive had them (computed instead).
    MeshData finish()
    {
        if (!anyNormals) out.normals.clear();
        if (!anyUvs) out.uvs.clear();
        if (!anyUvs1) out.uvs1.clear();
        if (!anyColors) out.colors.clear();
        out.tangentUvSet = normalMapSet.value_or(0);
        if (!allTangents || tangentUvs(out).empty() || out.normals.empty()) out.tangents.clear();
        return std::move(out);
    }
};

MeshData readMesh(const Document& d, uint32_t index, const std::vector<FileMaterial>& materials,
                  std::optional<uint32_t> variant, std::vector<std::string>& warnings)
{
    const json& mesh = (*d.array("meshes"))[index];
    const std::string where = indexed("meshes", index);
    const json* primitives = arrayMember(mesh, "primitives");
    if (!primitives || primitives->empty()) failInFile(d.file, where + ": a mesh needs at least one primitive");
    MeshBuilder builder{d, materials, warnings, variant, {}};
    for (size_t p = 0; p < primitives->size(); ++p)
        builder.addPrimitive((*primitives)[p], where + ".primitives[" + std::to_string(p) + "]");
    if (member(mesh, "weights") || std::any_of(primitives->begin(), primitives->end(),
                                               [](const json& p) { return member(p, "targets") != nullptr; }))
        builder.warnOnce("morph targets are not applied (meshes render in their base shape)");
    return builder.finish();
}

// -------------------------------------------------------------------- nodes

double finiteNumber(const fs::path& file, const json& value, const std::string& where)
{
    if (!value.is_number() || !std::isfinite(value.get<double>()))
        failInFile(file, where + ": expected finite numbers");
    return value.get<double>();
}

glm::dvec3 numbers3(const fs::path& file, const json& node, const char* key, glm::dvec3 fallback,
                    const std::string& where)
{
    const json* value = member(node, key);
    if (!value) return fallback;
    if (!value->is_array() || value->size() != 3) failInFile(file, where + "." + key + ": expected 3 numbers");
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) out[i] = finiteNumber(file, (*value)[size_t(i)], where + "." + key);
    return out;
}

glm::dmat4 trs(const glm::dvec3& t, const glm::dquat& r, const glm::dvec3& s)
{
    return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
}

/// A rotation quaternion (x, y, z, w) made unit; a zero one is an error.
glm::dquat unitQuaternion(const fs::path& file, const glm::dvec4& q, const std::string& where)
{
    const double length = glm::length(q);
    if (!(length > 0.0) || !std::isfinite(length)) failInFile(file, where + ": a rotation quaternion must not be zero");
    return glm::dquat(q.w / length, q.x / length, q.y / length, q.z / length);
}

/// A node's transform relative to its parent: `matrix` (column-major) or T R S, exactly.
glm::dmat4 localTransform(const fs::path& file, const json& node, const std::string& where)
{
    if (const json* m = member(node, "matrix")) {
        if (!m->is_array() || m->size() != 16) failInFile(file, where + ".matrix: expected 16 numbers");
        glm::dmat4 matrix;
        for (int i = 0; i < 16; ++i) matrix[i / 4][i % 4] = finiteNumber(file, (*m)[size_t(i)], where + ".matrix");
        return matrix;
    }
    glm::dvec4 q(0.0, 0.0, 0.0, 1.0);
    if (const json* r = member(node, "rotation")) {
        if (!r->is_array() || r->size() != 4) failInFile(file, where + ".rotation: expected a quaternion of 4 numbers");
        for (int i = 0; i < 4; ++i) q[i] = finiteNumber(file, (*r)[size_t(i)], where + ".rotation");
    }
    return trs(numbers3(file, node, "translation", glm::dvec3(0.0), where),
               unitQuaternion(file, q, where + ".rotation"), numbers3(file, node, "scale", glm::dvec3(1.0), where));
}

/// EXT_mesh_gpu_instancing's per-instance transforms (TRS), or one identity.
std::vector<glm::dmat4> instanceTransforms(const Document& d, const json& node, const std::string& where)
{
    const json* extensions = member(node, "extensions");
    const json* instancing = extensions ? member(*extensions, "EXT_mesh_gpu_instancing") : nullptr;
    const json* attributes = instancing ? member(*instancing, "attributes") : nullptr;
    if (!attributes) return {glm::dmat4(1.0)};
    const std::string name = where + ".extensions.EXT_mesh_gpu_instancing.attributes";
    std::optional<Accessor<>> t, r, s;
    uint64_t count = 0;
    auto read = [&](const char* key, uint32_t size, std::optional<Accessor<>>& into) {
        if (const auto index = uintMember(*attributes, key)) {
            const uint64_t declared = uintMember(d.element("accessors", *index, name), "count").value_or(0);
            if (declared > kMaxGltfInstances)
                failInFile(d.file, name + "." + key + ": " + std::to_string(declared) +
                                       " instances; vkrt reads at most " + std::to_string(kMaxGltfInstances));
            into = readAccessor(d, *index, {size}, name + "." + key);
            if (count != 0 && into->count != count)
                failInFile(d.file, name + ": TRANSLATION, ROTATION and SCALE must have the same count");
            count = into->count;
        }
    };
    read("TRANSLATION", 3, t);
    read("ROTATION", 4, r);
    read("SCALE", 3, s);
    if (count == 0) return {glm::dmat4(1.0)};
    if (count > kMaxGltfInstances)
        failInFile(d.file, name + ": " + std::to_string(count) + " instances; vkrt reads at most " +
                               std::to_string(kMaxGltfInstances));
    std::vector<glm::dmat4> out;
    out.reserve(count);
    for (uint64_t i = 0; i < count; ++i) {
        const glm::dvec3 translation = t ? glm::dvec3(t->at(i, 0), t->at(i, 1), t->at(i, 2)) : glm::dvec3(0.0);
        const glm::dvec4 q =
            r ? glm::dvec4(r->at(i, 0), r->at(i, 1), r->at(i, 2), r->at(i, 3)) : glm::dvec4(0, 0, 0, 1);
        const glm::dvec3 scale = s ? glm::dvec3(s->at(i, 0), s->at(i, 1), s->at(i, 2)) : glm::dvec3(1.0);
        if (!std::isfinite(glm::dot(translation, translation) + glm::dot(scale, scale)))
            failInFile(d.file, name + ": instance " + std::to_string(i) + " has a non-finite transform");
        out.push_back(
            trs(translation, unitQuaternion(d.file, q, name + ".ROTATION[" + std::to_string(i) + "]"), scale));
    }
    return out;
}

/// The chosen scene's index; nullopt when the file has no scenes.
std::optional<uint32_t> chosenScene(const Document& d, const std::optional<std::string>& choice)
{
    const json* scenes = d.array("scenes");
    const size_t count = scenes ? scenes->size() : 0;
    if (!choice) {
        if (count == 0) return std::nullopt;
        const uint32_t index = uintMember(d.doc, "scene").value_or(0);
        if (index >= count)
            failInFile(d.file, "scene: " + std::to_string(index) + " names a scene the file does not have");
        return index;
    }
    const std::string& text = *choice;
    const bool isIndex = !text.empty() && text.size() < 10 && text.find_first_not_of("0123456789") == std::string::npos;
    std::string known;
    for (size_t i = 0; i < count; ++i) {
        const std::string name = stringMember((*scenes)[i], "name");
        if ((isIndex && std::stoul(text) == i) || (!name.empty() && name == text)) return uint32_t(i);
        known += (known.empty() ? "" : ", ") + std::to_string(i) + (name.empty() ? "" : " ('" + name + "')");
    }
    throw InputError("--scene " + text + ": " + d.file.string() + " has no such scene (" +
                     (count == 0 ? std::string("it has none") : "its scenes: " + known) + ")");
}

/// KHR_materials_variants' variant `--variant` names (by name or index); nullopt without one.
std::optional<uint32_t> chosenVariant(const Document& d, const std::optional<std::string>& choice)
{
    if (!choice) return std::nullopt;
    const json* extensions = member(d.doc, "extensions");
    const json* block = extensions ? member(*extensions, "KHR_materials_variants") : nullptr;
    const json* variants = block ? arrayMember(*block, "variants") : nullptr;
    const size_t count = variants ? variants->size() : 0;
    const std::string& text = *choice;
    const bool isIndex = !text.empty() && text.size() < 10 && text.find_first_not_of("0123456789") == std::string::npos;
    std::string known;
    for (size_t i = 0; i < count; ++i) {
        const std::string name = stringMember((*variants)[i], "name");
        if ((isIndex && std::stoul(text) == i) || (!name.empty() && name == text)) return uint32_t(i);
        known += (known.empty() ? "" : ", ") + std::to_string(i) + (name.empty() ? "" : " ('" + name + "')");
    }
    throw InputError("--variant " + text + ": " + d.file.string() + " has no such material variant (" +
                     (count == 0 ? std::string("it has none") : "its variants: " + known) + ")");
}

/// The root nodes: the chosen scene's, or without scenes every node that is no child.
std::vector<uint32_t> rootNodes(const Document& d, std::optional<uint32_t> scene)
{
    const json* nodes = d.array("nodes");
    const size_t nodeCount = nodes ? nodes->size() : 0;
    std::vector<uint32_t> roots;
    if (scene) {
        if (const json* list = arrayMember((*d.array("scenes"))[*scene], "nodes"))
            for (const json& n : *list) {
                if (!n.is_number_unsigned() || n.get<uint64_t>() >= nodeCount)
                    failInFile(d.file, indexed("scenes", *scene) + ".nodes names a node the file does not have");
                roots.push_back(uint32_t(n.get<uint64_t>()));
            }
        return roots;
    }
    std::vector<bool> child(nodeCount, false);
    for (size_t i = 0; i < nodeCount; ++i)
        if (const json* children = arrayMember((*nodes)[i], "children"))
            for (const json& c : *children)
                if (c.is_number_unsigned() && c.get<uint64_t>() < nodeCount) child[c.get<uint64_t>()] = true;
    for (uint32_t i = 0; i < nodeCount; ++i)
        if (!child[i]) roots.push_back(i);
    return roots;
}

/// Placements already made, by mesh and exact transform. A placement that
/// repeats one draws the same surface in the same place again: nothing to
/// see, but every ray through it would test each copy (262,144 copies of a
/// triangle at the origin, 975 bytes of glTF, rendered at 711 samples/s).
class PlacementSet {
public:
    /// True the first time (mesh, transform) is seen.
    bool insert(uint32_t mesh, const glm::dmat4& transform)
    {
        Key key{mesh, {}};
        std::memcpy(key.matrix.data(), &transform[0][0], sizeof(double) * 16);
        return m_seen.insert(key).second;
    }

private:
    struct Key {
        uint32_t mesh;
        std::array<double, 16> matrix;
        /// Bit for bit, as the hash reads them (0.0 and -0.0 differ; a NaN is no transform here).
        bool operator==(const Key& other) const
        {
            return mesh == other.mesh && std::memcmp(matrix.data(), other.matrix.data(), sizeof matrix) == 0;
        }
    };
    struct KeyHash {
        size_t operator()(const Key& key) const
        {
            uint64_t hash = 1469598103934665603ull ^ key.mesh; // FNV-1a over the matrix's bytes
            const auto* bytes = reinterpret_cast<const unsigned char*>(key.matrix.data());
            for (size_t i = 0; i < sizeof(double) * 16; ++i) hash = (hash ^ bytes[i]) * 1099511628211ull;
            return size_t(hash);
        }
    };
    std::unordered_set<Key, KeyHash> m_seen;
};

void walkNodes(const Document& d, GltfModel& model, std::optional<uint32_t> scene)
{
    const json* nodes = d.array("nodes");
    if (!nodes) return;
    struct Visit {
        uint32_t node;
        glm::dmat4 parent;
    };
    std::vector<Visit> stack;
    const std::vector<uint32_t> roots = rootNodes(d, scene);
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
    const size_t meshCount = d.array("meshes") ? d.array("meshes")->size() : 0;
    bool singular = false;
    uint64_t visits = 0, repeated = 0;
    PlacementSet placements;
    // checkedGltfDocument refused cycles, second parents and deep hierarchies, and bounded the default
    // scene's walk; another scene's is bounded here.
    while (!stack.empty()) {
        const Visit visit = stack.back();
        stack.pop_back();
        if (++visits > kMaxGltfNodes)
            failInFile(d.file,
                       "the scene reaches more than " + withThousands(kMaxGltfNodes) +
                           " nodes (a node listed more than once among its roots is reached each time, with its "
                           "children); vkrt reads at most that many");
        const std::string where = indexed("nodes", visit.node);
        const json& node = (*nodes)[visit.node];
        if (!node.is_object()) failInFile(d.file, where + ": expected an object");
        const glm::dmat4 world = visit.parent * localTransform(d.file, node, where);
        const std::string name = stringMember(node, "name");
        if (const auto mesh = uintMember(node, "mesh")) {
            if (*mesh >= meshCount) failInFile(d.file, where + ".mesh names a mesh the file does not have");
            for (const glm::dmat4& instance : instanceTransforms(d, node, where)) {
                const glm::dmat4 placed = world * instance;
                const double det = glm::determinant(glm::dmat3(placed));
                if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
                    singular = true; // a zero scale hides a node (glTF viewers use it so): nothing to draw
                    continue;
                }
                if (!placements.insert(*mesh, placed)) {
                    ++repeated;
                    continue;
                }
                model.instances.push_back({*mesh, placed, name});
            }
            if (model.instances.size() > kMaxGltfInstances)
                failInFile(d.file, "the scene places meshes more than " + std::to_string(kMaxGltfInstances) +
                                       " times; vkrt reads at most that many instances");
        }
        if (const auto camera = uintMember(node, "camera")) model.cameras.push_back({*camera, visit.node, name, world});
        if (const json* extensions = member(node, "extensions"))
            if (const json* light = member(*extensions, "KHR_lights_punctual"))
                if (const auto index = uintMember(*light, "light"))
                    model.lights.push_back({*index, visit.node, name, world});
        if (const json* children = arrayMember(node, "children"))
            for (size_t c = children->size(); c-- > 0;)
                if (const json& child = (*children)[c];
                    child.is_number_unsigned() && child.get<uint64_t>() < nodes->size())
                    stack.push_back({uint32_t(child.get<uint64_t>()), world});
    }
    if (singular) model.warnings.push_back("nodes with a zero scale (a singular transform) are not drawn");
    if (repeated > 0)
        model.warnings.push_back(withThousands(repeated) +
                                 " mesh placements repeat an earlier one exactly (the same mesh, the same transform) "
                                 "and are drawn once");
}

// --------------------------------------------------- cameras and lights

double number(const fs::path& file, const json& object, const char* key, double fallback, const std::string& where)
{
    const json* value = member(object, key);
    if (!value) return fallback;
    if (!value->is_number() || !std::isfinite(value->get<double>()))
        failInFile(file, where + "." + key + ": expected a finite number");
    return value->get<double>();
}

/// 1e+39, 0.5: a number for messages, six significant digits.
std::string shortNumber(double value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

GltfCamera readCamera(const fs::path& file, const json& camera, const std::string& where)
{
    GltfCamera c;
    c.name = stringMember(camera, "name");
    const std::string type = stringMember(camera, "type");
    if (type == "orthographic") {
        const json* o = member(camera, "orthographic");
        if (!o || !o->is_object()) failInFile(file, where + ": an orthographic camera needs its `orthographic` object");
        c.orthographic = true;
        c.xmag = number(file, *o, "xmag", 0.0, where + ".orthographic");
        c.ymag = number(file, *o, "ymag", 0.0, where + ".orthographic");
        if (c.xmag == 0.0 || c.ymag == 0.0)
            failInFile(file, where + ".orthographic: xmag and ymag must be given and not zero");
        // The view's size reaches the kernel in float32: 1e39 is finite here, infinite there (a black image).
        if (std::abs(c.xmag) > kMaxKernelMagnitude || std::abs(c.ymag) > kMaxKernelMagnitude)
            failInFile(file, where + ".orthographic: xmag and ymag must be at most " +
                                 shortNumber(kMaxKernelMagnitude) +
                                 " in magnitude (the kernel's float32 holds lengths up to that), got " +
                                 shortNumber(c.xmag) + " and " + shortNumber(c.ymag));
        return c;
    }
    if (type != "perspective")
        failInFile(file, where + ".type: must be \"perspective\" or \"orthographic\", got '" + type + "'");
    const json* p = member(camera, "perspective");
    if (!p || !p->is_object()) failInFile(file, where + ": a perspective camera needs its `perspective` object");
    c.yfov = number(file, *p, "yfov", 0.0, where + ".perspective");
    if (!(c.yfov > 0.0 && c.yfov < 3.141592653589793))
        failInFile(file, where + ".perspective.yfov: must be strictly between 0 and pi radians");
    if (member(*p, "aspectRatio")) {
        c.aspectRatio = number(file, *p, "aspectRatio", 1.0, where + ".perspective");
        if (!(*c.aspectRatio > 0.0)) failInFile(file, where + ".perspective.aspectRatio: must be > 0");
    }
    return c;
}

GltfLight readLight(const fs::path& file, const json& light, const std::string& where)
{
    if (!light.is_object()) failInFile(file, where + ": expected an object with a `type`");
    GltfLight l;
    l.name = stringMember(light, "name");
    l.type = stringMember(light, "type");
    if (l.type != "point" && l.type != "spot" && l.type != "directional")
        failInFile(file, where + ".type: unknown light type '" + l.type + "' (point, spot, directional)");
    l.color = numbers3(file, light, "color", glm::dvec3(1.0), where);
    l.intensity = number(file, light, "intensity", 1.0, where);
    if (!(l.intensity >= 0.0) || glm::any(glm::lessThan(l.color, glm::dvec3(0.0))))
        failInFile(file, where + ": color and intensity must be >= 0");
    if (std::max({l.color.r, l.color.g, l.color.b}) * l.intensity > std::numeric_limits<float>::max())
        failInFile(file, where + ": color x intensity is beyond 32-bit float range");
    l.hasRange = member(light, "range") != nullptr;
    if (l.type == "spot") {
        const json* spot = member(light, "spot");
        const json empty = json::object();
        const json& s = spot ? *spot : empty;
        l.innerConeAngle = number(file, s, "innerConeAngle", 0.0, where + ".spot");
        l.outerConeAngle = number(file, s, "outerConeAngle", l.outerConeAngle, where + ".spot");
        if (!(l.outerConeAngle > 0.0 && l.outerConeAngle <= 3.141592653589793 / 2.0) ||
            !(l.innerConeAngle >= 0.0 && l.innerConeAngle <= l.outerConeAngle))
            failInFile(file,
                       where + ".spot: needs 0 <= innerConeAngle <= outerConeAngle <= pi/2 and outerConeAngle > 0");
    }
    return l;
}

void readCamerasAndLights(const Document& d, GltfModel& model)
{
    if (const json* cameras = d.array("cameras"))
        for (size_t i = 0; i < cameras->size(); ++i)
            model.cameraDefinitions.push_back(readCamera(d.file, (*cameras)[i], indexed("cameras", i)));
    const json* extensions = member(d.doc, "extensions");
    const json* punctual = extensions ? member(*extensions, "KHR_lights_punctual") : nullptr;
    if (const json* lights = punctual ? arrayMember(*punctual, "lights") : nullptr)
        for (size_t i = 0; i < lights->size(); ++i)
            model.lightDefinitions.push_back(
                readLight(d.file, (*lights)[i], "extensions.KHR_lights_punctual." + indexed("lights", i)));
    for (const GltfPlaced& c : model.cameras)
        if (c.index >= model.cameraDefinitions.size())
            failInFile(d.file, indexed("nodes", c.node) + ".camera names a camera the file does not have");
    for (const GltfPlaced& l : model.lights)
        if (l.index >= model.lightDefinitions.size())
            failInFile(d.file, indexed("nodes", l.node) + " names a KHR_lights_punctual light the file does not have");
}

// --------------------------------------------------------------- extensions

void checkExtensions(const Document& d, GltfModel& model)
{
    const std::vector<std::string>& implemented = implementedGltfExtensions();
    auto known = [&](const std::string& name) {
        return std::find(implemented.begin(), implemented.end(), name) != implemented.end();
    };
    if (const json* required = d.array("extensionsRequired"))
        for (const json& name : *required)
            if (name.is_string() && !known(name.get<std::string>()))
                failInFile(d.file, "extensionsRequired names " + name.get<std::string>() +
                                       ", which vkrt does not implement (the file cannot be rendered without it)");
    if (const json* used = d.array("extensionsUsed"))
        for (const json& name : *used)
            if (name.is_string() && !known(name.get<std::string>()))
                model.warnings.push_back("extension " + name.get<std::string>() +
                                         " is not supported: what it adds is ignored");
}

} // namespace

const std::vector<std::string>& implementedGltfExtensions()
{
    static const std::vector<std::string> names{
        "KHR_lights_punctual",       "KHR_texture_transform",    "KHR_materials_emissive_strength",
        "KHR_materials_ior",         "KHR_mesh_quantization",    "EXT_mesh_gpu_instancing",
        "KHR_materials_unlit",       "KHR_materials_variants",   "KHR_materials_transmission",
        "KHR_materials_specular",    "KHR_materials_sheen",      "KHR_materials_clearcoat",
        "KHR_materials_iridescence", "KHR_materials_anisotropy",
        "KHR_materials_volume", // its attenuation (the thickness only decides thin-walled or not)
    };
    return names;
}

GltfModel readGltfModel(const fs::path& file, const GltfReadOptions& options)
{
    const Document d = openDocument(file, options.references);
    GltfModel model;
    model.file = file;
    model.referencedFiles = d.bufferFiles;
    checkExtensions(d, model);
    const auto viewBytes = [&](uint32_t view, const std::string& where) {
        const json& v = d.element("bufferViews", view, where);
        const uint64_t length = uintMember(v, "byteLength").value_or(0);
        const char* bytes = d.viewBytes(view, 0, length, where);
        return std::vector<uint8_t>(bytes, bytes + length);
    };
    model.materials = readGltfMaterials(d.doc, file, d.references, viewBytes);
    const std::optional<uint32_t> scene = chosenScene(d, options.scene);
    const std::optional<uint32_t> variant = chosenVariant(d, options.variant);
    model.sceneIndex = scene.value_or(0);
    if (scene) model.sceneName = stringMember((*d.array("scenes"))[*scene], "name");
    walkNodes(d, model, scene);
    readCamerasAndLights(d, model);
    // Only meshes the scene places are read: a file's other scenes may hold meshes it never shows.
    const size_t meshCount = d.array("meshes") ? d.array("meshes")->size() : 0;
    model.meshes.resize(meshCount);
    model.meshNames.resize(meshCount);
    std::vector<bool> placed(meshCount, false);
    for (const GltfInstance& instance : model.instances) placed[instance.mesh] = true;
    for (uint32_t m = 0; m < meshCount; ++m) {
        model.meshNames[m] = stringMember((*d.array("meshes"))[m], "name");
        if (placed[m]) model.meshes[m] = readMesh(d, m, model.materials, variant, model.warnings);
    }
    std::erase_if(model.instances, [&](const GltfInstance& i) { return model.meshes[i.mesh].triangles.empty(); });
    return model;
}

// --------------------------------------------------------------- flattening

namespace {

/// Appends one instance of `mesh` transformed by `world`, its materials renumbered through `materialMap`.
void appendInstance(MeshData& out, const MeshData& mesh, const glm::dmat4& world,
                    const std::vector<uint32_t>& materialMap)
{
    const auto base = uint32_t(out.positions.size());
    const glm::dmat3 linear(world);
    const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(linear));
    const bool mirrored = glm::determinant(linear) < 0.0;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        out.positions.push_back(glm::vec3(world * glm::dvec4(glm::dvec3(mesh.positions[v]), 1.0)));
        if (!mesh.normals.empty()) {
            const glm::dvec3 n = normalMatrix * glm::dvec3(mesh.normals[v]);
            const double length = glm::length(n);
            out.normals.push_back(length > 0.0 && std::isfinite(length) ? glm::vec3(n / length) : glm::vec3(0.0f));
        }
        if (!mesh.tangents.empty()) {
            const glm::dvec3 t = linear * glm::dvec3(mesh.tangents[v]);
            const double length = glm::length(t);
            const float w = mesh.tangents[v].w * (mirrored ? -1.0f : 1.0f);
            out.tangents.push_back(length > 0.0 && std::isfinite(length) ? glm::vec4(glm::vec3(t / length), w)
                                                                         : glm::vec4(0.0f));
        }
        if (!mesh.uvs.empty()) out.uvs.push_back(mesh.uvs[v]);
        if (!mesh.uvs1.empty()) out.uvs1.push_back(mesh.uvs1[v]);
        if (!mesh.colors.empty()) out.colors.push_back(mesh.colors[v]);
    }
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const glm::uvec3 tri = mesh.triangles[t] + base;
        // A mirroring transform turns the winding round; glTF keeps the front side (3.7.4).
        out.triangles.push_back(mirrored ? glm::uvec3(tri.x, tri.z, tri.y) : tri);
        out.triangleMaterials.push_back(materialMap[mesh.triangleMaterials[t]]);
    }
}

} // namespace

MeshData flattenGltfModel(GltfModel model)
{
    uint64_t triangles = 0, vertices = 0;
    for (const GltfInstance& i : model.instances) {
        triangles += model.meshes[i.mesh].triangles.size();
        vertices += model.meshes[i.mesh].positions.size();
    }
    if (triangles == 0)
        failInFile(model.file, "no triangles in " + model.file.string() + " (its scene places no triangle mesh)");
    if (triangles > kMaxGltfTriangles)
        failInFile(model.file,
                   "the node hierarchy instances meshes " + withThousands(model.instances.size()) + " times, " +
                       withThousands(triangles) + " triangles in all; vkrt reads at most " +
                       withThousands(kMaxGltfTriangles) +
                       " triangles after instancing into one mesh (a glTF scene keeps its instances instead: "
                       "render the file itself, or `[import] gltf` it)");
    if (vertices > UINT32_MAX) failInFile(model.file, "more than 2^32 vertices after instancing");
    // Attributes are all or nothing in MeshData: a mesh without one gets neutral values.
    auto any = [&](auto member) {
        return std::any_of(model.instances.begin(), model.instances.end(),
                           [&](const GltfInstance& i) { return !(model.meshes[i.mesh].*member).empty(); });
    };
    auto all = [&](auto member) {
        return std::all_of(model.instances.begin(), model.instances.end(),
                           [&](const GltfInstance& i) { return !(model.meshes[i.mesh].*member).empty(); });
    };
    const bool normals = any(&MeshData::normals), uvs = any(&MeshData::uvs), uvs1 = any(&MeshData::uvs1);
    const bool colors = any(&MeshData::colors);
    // One tangent set for the joined mesh: kept only where every mesh has tangents of the same uv set.
    const uint32_t tangentSet = model.instances.empty() ? 0 : model.meshes[model.instances.front().mesh].tangentUvSet;
    const bool tangents = all(&MeshData::tangents) &&
                          std::all_of(model.instances.begin(), model.instances.end(), [&](const GltfInstance& i) {
                              return model.meshes[i.mesh].tangentUvSet == tangentSet;
                          });
    for (MeshData& mesh : model.meshes) {
        if (normals && mesh.normals.empty()) mesh.normals.assign(mesh.positions.size(), glm::vec3(0.0f));
        if (uvs && mesh.uvs.empty()) mesh.uvs.assign(mesh.positions.size(), glm::vec2(0.0f));
        if (uvs1 && mesh.uvs1.empty()) mesh.uvs1.assign(mesh.positions.size(), glm::vec2(0.0f));
        if (colors && mesh.colors.empty()) mesh.colors.assign(mesh.positions.size(), glm::vec4(1.0f));
        if (!tangents) mesh.tangents.clear();
    }
    // The materials the placed triangles use, in order of first use.
    std::vector<uint32_t> materialMap(model.materials.size(), UINT32_MAX);
    std::vector<bool> seen(model.meshes.size(), false);
    MeshData out;
    for (const GltfInstance& i : model.instances) {
        if (seen[i.mesh]) continue;
        seen[i.mesh] = true;
        for (uint32_t m : model.meshes[i.mesh].triangleMaterials)
            if (materialMap[m] == UINT32_MAX) {
                materialMap[m] = uint32_t(out.materials.size());
                out.materials.push_back(model.materials[m]);
            }
    }
    // What the file as a whole does not honour reaches the scene's warnings through the first material.
    if (!model.lights.empty())
        model.warnings.push_back("KHR_lights_punctual: a mesh object brings no lights (import the file as a scene, "
                                 "`[import] gltf`, to have them)");
    for (const std::string& warning : model.warnings) out.materials.front().unsupported.push_back(warning);
    out.positions.reserve(vertices);
    out.triangles.reserve(triangles);
    out.tangentUvSet = tangentSet;
    out.referencedFiles = std::move(model.referencedFiles);
    for (const GltfInstance& i : model.instances) appendInstance(out, model.meshes[i.mesh], i.world, materialMap);
    return out;
}

} // namespace vkrt
