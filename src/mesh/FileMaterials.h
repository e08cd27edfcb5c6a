#pragma once
// The materials a glTF 2.0 file brings with its meshes (metallic-roughness),
// as the file states them: factors, textures (named, not loaded) and what of
// the material vkrt will not honour. Read by loadMeshFile (MeshLoader.h) into
// MeshData::materials; the scene side turns them into `pbr` materials and
// loads the textures (TextureAtlas), so a missing texture file is reported
// there, at the scene's location, not here.
//
// Honoured: baseColorFactor/Texture, metallicFactor, roughnessFactor,
// metallicRoughnessTexture (G = roughness, B = metallic), normalTexture and
// its scale, emissiveFactor/Texture, doubleSided, the samplers' wrap modes.
// Listed in `unsupported`: every extension the material or its textures use
// (KHR_texture_transform, KHR_materials_*, ...), extensions the file uses
// outside its materials, textures read through a TEXCOORD other than 0,
// alphaMode MASK and BLEND (rendered opaque). Not listed, documented here:
// occlusionTexture, which a path tracer has no use for (it computes the
// occlusion), and the samplers' filters (vkrt filters with its own mip maps).
#include "mesh/ReferencePolicy.h"
#include "texture/TextureAtlas.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

struct aiScene;

namespace vkrt {

/// An image a material names: a file beside the glTF, or bytes inside it.
struct FileTexture {
    std::filesystem::path file;    ///< resolved against the glTF's folder; empty when embedded
    std::vector<uint8_t> embedded; ///< bytes of an embedded image (.glb, data: URIs), else empty
    std::string name;              ///< for messages: the URI, or "embedded image N of FILE"
    TextureWrap wrapU = TextureWrap::Repeat;
    TextureWrap wrapV = TextureWrap::Repeat;
};

/// glTF's alphaMode. vkrt renders every mode opaque (MASK and BLEND are listed as unsupported).
enum class AlphaMode { Opaque, Mask, Blend };

/// One glTF metallic-roughness material; defaults are glTF's (its default material).
struct FileMaterial {
    std::string name;                            ///< the file's name, or "" (glTF names are optional)
    int fileIndex = -1;                          ///< its index in the file's `materials`; -1: glTF's default material
    glm::vec4 baseColorFactor{1.0f};             ///< linear RGBA, each in [0, 1]
    std::optional<FileTexture> baseColorTexture; ///< sRGB
    float metallicFactor = 1.0f;                 ///< [0, 1]
    float roughnessFactor = 1.0f;                ///< [0, 1], perceptual (alpha = roughness^2)
    std::optional<FileTexture> metallicRoughnessTexture; ///< linear; G = roughness, B = metallic
    std::optional<FileTexture> normalTexture;            ///< linear, tangent space (MeshData::tangents)
    float normalScale = 1.0f;                            ///< scales the normal map's X and Y
    glm::vec3 emissiveFactor{0.0f};                      ///< linear RGB, >= 0
    std::optional<FileTexture> emissiveTexture;          ///< sRGB
    AlphaMode alphaMode = AlphaMode::Opaque;
    float alphaCutoff = 0.5f; ///< for MASK
    bool doubleSided = false;
    std::vector<std::string> unsupported; ///< what vkrt will not honour, one readable phrase each
};

/// The materials of a glTF 2.0 file that assimp imported as `scene`, one per
/// aiScene material (the same indices: assimp appends glTF's default material
/// last, for primitives without one). Throws InputError naming `file` for a
/// malformed material (non-finite or out-of-range factor, an embedded image
/// that is not there). A glTF 1.0 file, whose materials are not
/// metallic-roughness, gives an empty list. An image file that `references`
/// refuses (outside the glTF's folder) is an InputError too.
std::vector<FileMaterial> readGltfMaterials(const aiScene& scene, const std::filesystem::path& file,
                                            const ReferencePolicy& references);

/// The glTF JSON of a .gltf file or of a .glb's first chunk; throws InputError naming `file`.
std::string readGltfJson(const std::filesystem::path& file);

/// The most levels of arrays and objects the glTF JSON may nest (assimp's
/// rapidjson parses recursively and overflows its stack near 100,000).
constexpr size_t kMaxGltfJsonNesting = 1024;
/// The most levels of the node hierarchy (a root node is level 1): assimp
/// recurses once per level and crashes on a chain of 30,000 nodes.
constexpr uint32_t kMaxGltfNodeDepth = 1024;

/// Checks, before assimp reads the file, what assimp would trust:
/// - every accessor lies inside its bufferView and every bufferView inside
///   its buffer's byteLength (assimp 5.2.5 copies accessor data without that
///   check: a heap overflow the fuzzer found);
/// - the JSON nests at most kMaxGltfJsonNesting levels, and the node
///   hierarchy is a set of trees (no cycle, at most one parent per node) at
///   most kMaxGltfNodeDepth levels deep;
/// - every buffer and image file URI is one `references` allows.
/// Throws InputError naming `file` and the accessor, view, node, buffer or
/// image, or for JSON that cannot be parsed or repeats a key in an object
/// (which assimp's parser and ours would read differently). Fields of the
/// wrong type are left to assimp, which reports them.
void checkGltfBeforeImport(const std::filesystem::path& file, const ReferencePolicy& references);

} // namespace vkrt
