#include "support/GltfTestFiles.h"

#include <algorithm>
#include <fstream>

namespace vkrt::test {

std::string base64(const std::string& bytes)
{
    static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const size_t n = std::min<size_t>(3, bytes.size() - i);
        uint32_t word = 0;
        for (size_t k = 0; k < 3; ++k) word = (word << 8) | (k < n ? uint8_t(bytes[i + k]) : 0u);
        for (size_t k = 0; k < 4; ++k) out.push_back(k <= n ? alphabet[(word >> (18 - 6 * k)) & 63] : '=');
    }
    return out;
}

std::string dataUri(const std::string& type, const std::string& bytes)
{
    return "data:" + type + ";base64," + base64(bytes);
}

std::string triangleBuffer()
{
    std::string bytes;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(bytes, v); // 0: 36 bytes
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) put(bytes, v);                // 36: 24 bytes
    for (float v : {0.f, 0.f, 1.f, 0.f, 0.f, 1.f}) put(bytes, v);                // 60: 24 bytes
    for (uint16_t i : {0, 1, 2}) put(bytes, i);                                  // 84: 6 bytes
    bytes.append(2, '\0');
    return bytes;
}

std::string triangleGltf(const std::string& rest, const std::string& material)
{
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{)" +
           material + R"("attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}, "indices": 3}]}],
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", triangleBuffer()) + R"(", "byteLength": 92}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 24}, {"buffer": 0, "byteOffset": 84, "byteLength": 6}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}],
  )" + rest +
           "}";
}

std::string quadsGltf(const std::vector<GltfQuad>& quads, const std::string& rest)
{
    std::string positions, uvs, uvs1, indices;
    const bool second = !quads.empty() && quads.front().uv1.has_value();
    float lower[3] = {1e30f, 1e30f, 1e30f}, upper[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t q = 0; q < quads.size(); ++q) {
        for (int k = 0; k < 4; ++k) {
            for (int c = 0; c < 3; ++c) {
                put(positions, quads[q].p[k][c]);
                lower[c] = std::min(lower[c], quads[q].p[k][c]);
                upper[c] = std::max(upper[c], quads[q].p[k][c]);
            }
            for (int c = 0; c < 2; ++c) put(uvs, quads[q].uv[k][c]);
            for (int c = 0; c < 2 && second; ++c) put(uvs1, quads[q].uv1.value_or(quads[q].uv)[k][c]);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) put(indices, uint32_t(4 * q + i));
    }
    const std::string bytes = positions + uvs + indices + uvs1;
    const size_t n = 4 * quads.size();
    auto number = [](size_t v) { return std::to_string(v); };
    auto vec3 = [](const float* v) {
        return "[" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + "]";
    };
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"material": 0, "attributes": {"POSITION": 0, "TEXCOORD_0": 1)" +
           std::string(second ? R"(, "TEXCOORD_1": 3)" : "") + R"(}, "indices": 2}]}],
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", bytes) + R"(", "byteLength": )" + number(bytes.size()) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" +
           number(positions.size()) + R"(}, {"buffer": 0, "byteOffset": )" + number(positions.size()) +
           R"(, "byteLength": )" + number(uvs.size()) + R"(}, {"buffer": 0, "byteOffset": )" +
           number(positions.size() + uvs.size()) + R"(, "byteLength": )" + number(indices.size()) + "}" +
           (second ? R"(, {"buffer": 0, "byteOffset": )" + number(positions.size() + uvs.size() + indices.size()) +
                         R"(, "byteLength": )" + number(uvs1.size()) + "}"
                   : "") +
           R"(],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": )" +
           number(n) + R"(, "type": "VEC3", "min": )" + vec3(lower) + R"(, "max": )" + vec3(upper) + R"(},
    {"bufferView": 1, "componentType": 5126, "count": )" +
           number(n) + R"(, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5125, "count": )" +
           number(6 * quads.size()) + R"(, "type": "SCALAR"})" +
           (second ? R"(, {"bufferView": 3, "componentType": 5126, "count": )" + number(n) + R"(, "type": "VEC2"})"
                   : "") +
           R"(],
  )" + rest +
           "}";
}

GltfBuilder::GltfBuilder()
{
    m_doc = {{"asset", {{"version", "2.0"}}},
             {"bufferViews", json::array()},
             {"accessors", json::array()},
             {"meshes", json::array()},
             {"nodes", json::array()}};
}

uint32_t GltfBuilder::bufferView(const std::string& bytes)
{
    while (m_bin.size() % 4) m_bin.push_back('\0');
    m_doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", m_bin.size()}, {"byteLength", bytes.size()}});
    m_bin += bytes;
    return uint32_t(m_doc["bufferViews"].size() - 1);
}

uint32_t GltfBuilder::mesh(json attributes, std::optional<uint32_t> indexAccessor, uint32_t mode,
                           std::optional<uint32_t> material)
{
    json primitive = {{"attributes", attributes}, {"mode", mode}};
    if (indexAccessor) primitive["indices"] = *indexAccessor;
    if (material) primitive["material"] = *material;
    m_doc["meshes"].push_back({{"primitives", json::array({primitive})}});
    return uint32_t(m_doc["meshes"].size() - 1);
}

uint32_t GltfBuilder::node(json node)
{
    m_doc["nodes"].push_back(node);
    return uint32_t(m_doc["nodes"].size() - 1);
}

std::filesystem::path GltfBuilder::write(const std::filesystem::path& path) const
{
    json doc = m_doc;
    doc["buffers"] = json::array({{{"byteLength", m_bin.size()}, {"uri", dataUri("application/octet-stream", m_bin)}}});
    std::ofstream(path, std::ios::binary) << doc.dump();
    return path;
}

std::filesystem::path GltfBuilder::writeGlb(const std::filesystem::path& path) const
{
    json doc = m_doc;
    std::string bin = m_bin;
    while (bin.size() % 4) bin.push_back('\0');
    doc["buffers"] = json::array({{{"byteLength", m_bin.size()}}});
    std::ofstream(path, std::ios::binary) << glbBytes(doc.dump(), bin);
    return path;
}

std::string glbBytes(const std::string& json, const std::string& bin, uint32_t version, bool padJson)
{
    std::string text = json;
    while (padJson && text.size() % 4) text.push_back(' ');
    std::string out = "glTF";
    put(out, version);
    put(out, uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
    put(out, uint32_t(text.size()));
    out += "JSON" + text;
    if (!bin.empty()) {
        put(out, uint32_t(bin.size()));
        out += std::string("BIN\0", 4) + bin;
    }
    return out;
}

} // namespace vkrt::test
