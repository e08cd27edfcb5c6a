#pragma once
// glTF files written by tests: base64 data: URIs, little-endian buffers and a
// one-triangle glTF whose materials, textures and samplers the test supplies.
#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt::test {

/// RFC 4648 base64, for data: URIs.
std::string base64(const std::string& bytes);

/// "data:TYPE;base64,..."
std::string dataUri(const std::string& type, const std::string& bytes);

/// Appends the bytes of `value` (little-endian on the machines vkrt runs on).
template <typename T>
void put(std::string& out, T value)
{
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

/// The buffer of triangleGltf: POSITION (0,0,0) (1,0,0) (0,1,0), TEXCOORD_0 and
/// TEXCOORD_1 (0,0) (1,0) (0,1), indices 0 1 2; 92 bytes.
std::string triangleBuffer();

/// A one-triangle glTF 2.0 (buffer inline as a data: URI) whose primitive
/// has `material` ("\"material\": 0, " or "") and whose top-level object
/// ends with `rest` (materials, textures, images, samplers, extensions...).
std::string triangleGltf(const std::string& rest, const std::string& material = R"("material": 0, )");

/// A quad of a quadsGltf: corners p[0..3] (two triangles 0 1 2 and 0 2 3,
/// counter-clockwise seen from the side they face) and their TEXCOORD_0 in
/// glTF's convention (v down from the image's top row).
struct GltfQuad {
    std::array<std::array<float, 3>, 4> p;
    std::array<std::array<float, 2>, 4> uv;
    /// TEXCOORD_1, the same way: written for every quad when the first quad has it.
    std::optional<std::array<std::array<float, 2>, 4>> uv1 = std::nullopt;
};

/// A glTF 2.0 of one mesh of quads (buffer inline), every triangle of
/// material 0; its top-level object ends with `rest` (materials, textures,
/// images, samplers, extensionsUsed...).
std::string quadsGltf(const std::vector<GltfQuad>& quads, const std::string& rest);

/// A glTF 2.0 document built in memory: accessors over one binary buffer,
/// meshes, nodes; written as a .gltf with the buffer inline (a data: URI) or
/// as a .glb with the buffer as its BIN chunk.
class GltfBuilder {
public:
    using json = nlohmann::json;

    GltfBuilder();

    /// An accessor over tightly packed values of one component type.
    template <typename T>
    uint32_t accessor(const std::vector<T>& values, const char* type, uint32_t componentType, bool normalized = false)
    {
        const uint32_t components = std::string(type) == "SCALAR" ? 1 : uint32_t(type[3] - '0');
        const uint32_t view = bufferView(valueBytes(values));
        json a = {{"bufferView", view},
                  {"componentType", componentType},
                  {"count", values.size() / components},
                  {"type", type}};
        if (normalized) a["normalized"] = true;
        m_doc["accessors"].push_back(a);
        return uint32_t(m_doc["accessors"].size() - 1);
    }
    uint32_t floats(const std::vector<float>& v, const char* type) { return accessor(v, type, 5126); }
    uint32_t indices(const std::vector<uint32_t>& v) { return accessor(v, "SCALAR", 5125); }
    /// A bufferView over `bytes` appended to the buffer (4-byte aligned); returns its index.
    uint32_t bufferView(const std::string& bytes);

    /// A mesh of one primitive with the given attributes; returns its index.
    uint32_t mesh(json attributes, std::optional<uint32_t> indexAccessor = {}, uint32_t mode = 4,
                  std::optional<uint32_t> material = {});
    uint32_t node(json node);

    json& doc() { return m_doc; }
    /// The document with its buffer as a data: URI, written to `path`.
    std::filesystem::path write(const std::filesystem::path& path) const;
    /// The document and its buffer as a binary glTF (its JSON chunk padded with spaces), written to `path`.
    std::filesystem::path writeGlb(const std::filesystem::path& path) const;

private:
    template <typename T>
    static std::string valueBytes(const std::vector<T>& values)
    {
        std::string bytes;
        for (T v : values) put(bytes, v);
        return bytes;
    }
    json m_doc;
    std::string m_bin;
};

/// A binary glTF: the 12-byte header (magic, `version`, length), the JSON
/// chunk (padded with spaces to 4 bytes unless `padJson` is false) and, when
/// `bin` is not empty, the BIN chunk.
std::string glbBytes(const std::string& json, const std::string& bin, uint32_t version = 2, bool padJson = true);

} // namespace vkrt::test
