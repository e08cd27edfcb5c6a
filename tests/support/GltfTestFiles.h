#pragma once
// glTF files written by tests: base64 data: URIs, little-endian buffers and a
// one-triangle glTF whose materials, textures and samplers the test supplies.
#include <array>
#include <cstdint>
#include <cstring>
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

} // namespace vkrt::test
