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
// its scale, emissiveFactor/Texture, doubleSided, the samplers' wrap modes and
// filters (an undefined filter is vkrt's default: bilinear magnification,
// trilinear minification over vkrt's own mip maps),
// KHR_materials_emissive_strength, _ior, _specular, _sheen, _clearcoat,
// _transmission, _volume and _iridescence (the pbr material's layers:
// scene/FileMaterialImport.cpp), and KHR_texture_transform on every texture
// (a normal map's tangent frame is not turned with its uvs).
// Listed in `unsupported`: extensions on a texture other than KHR_texture_transform.
// alphaMode and alphaCutoff are read (MASK and BLEND are honoured: alpha is
// baseColorFactor.a times the base colour texture's A). Not listed, documented here:
// occlusionTexture, which a path tracer has no use for (it computes the
// occlusion).
#include "mesh/AlphaMode.h"
#include "mesh/ReferencePolicy.h"
#include "texture/TextureAtlas.h"

#include <glm/glm.hpp>

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vkrt {

/// An image a material names: a file beside the glTF, or bytes inside it.
struct FileTexture {
    std::filesystem::path file; ///< resolved against the glTF's folder; empty when embedded
    /// Bytes of an embedded image (.glb, data: URIs), else null; one copy per
    /// image, shared by every slot that names it (TextureAtlas decodes it once).
    std::shared_ptr<const std::vector<uint8_t>> embedded;
    std::string name;      ///< for messages: the URI, or "embedded image N of FILE"
    uint32_t texCoord = 0; ///< the TEXCOORD_n set it reads (KHR_texture_transform's override applied)
    TextureWrap wrapU = TextureWrap::Repeat;
    TextureWrap wrapV = TextureWrap::Repeat;
    TextureFilter filter; ///< the sampler's magFilter and minFilter (absent: vkrt's trilinear default)
    /// KHR_texture_transform (MaterialTexture's convention): offset, rotation (radians), scale.
    glm::dvec2 offset{0.0};
    double rotation = 0.0;
    glm::dvec2 scale{1.0};
};

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
    /// KHR_materials_transmission's transmissionFactor (R of its texture) and
    /// KHR_materials_ior's ior (glTF's defaults 0 and 1.5).
    float transmission = 0.0f;
    std::optional<FileTexture> transmissionTexture;
    float ior = 1.5f;
    /// KHR_materials_unlit: the base colour is what the camera sees, no lighting.
    bool unlit = false;
    /// KHR_materials_specular (glTF's defaults): strength (A of its texture) and F0 colour (sRGB texture).
    float specularFactor = 1.0f;
    std::optional<FileTexture> specularTexture;
    glm::vec3 specularColorFactor{1.0f}; ///< >= 0, may exceed 1
    std::optional<FileTexture> specularColorTexture;
    /// KHR_materials_sheen: colour (sRGB texture) and roughness (A of its texture).
    glm::vec3 sheenColorFactor{0.0f};
    std::optional<FileTexture> sheenColorTexture;
    float sheenRoughnessFactor = 0.0f;
    std::optional<FileTexture> sheenRoughnessTexture;
    /// KHR_materials_clearcoat: strength (R of its texture), roughness (G of its texture), the coat's own normal map.
    float clearcoatFactor = 0.0f;
    std::optional<FileTexture> clearcoatTexture;
    float clearcoatRoughnessFactor = 0.0f;
    std::optional<FileTexture> clearcoatRoughnessTexture;
    std::optional<FileTexture> clearcoatNormalTexture;
    float clearcoatNormalScale = 1.0f; ///< scales the coat's normal map's X and Y
    /// KHR_materials_anisotropy: strength (times B of its texture), rotation in radians from the tangent (the
    /// texture's RG: the direction in the tangent frame, which the rotation turns).
    float anisotropyStrength = 0.0f;
    float anisotropyRotation = 0.0f;
    std::optional<FileTexture> anisotropyTexture;
    /// KHR_materials_iridescence: strength (R of its texture), the film's index and its thickness in nm
    /// (the maximum, or mixed from the minimum by G of its texture).
    float iridescenceFactor = 0.0f;
    std::optional<FileTexture> iridescenceTexture;
    float iridescenceIor = 1.3f;
    float iridescenceThicknessMinimum = 100.0f;
    float iridescenceThicknessMaximum = 400.0f;
    std::optional<FileTexture> iridescenceThicknessTexture;
    /// KHR_materials_volume: thickness (0: thin-walled) and Beer-Lambert attenuation (world units).
    float thicknessFactor = 0.0f;
    float attenuationDistance = std::numeric_limits<float>::infinity();
    glm::vec3 attenuationColor{1.0f};
    /// Every texture slot above, in one list (for what reads every texture: uv sets, transforms).
    std::vector<const std::optional<FileTexture>*> textureSlots() const;
    std::vector<std::string> unsupported; ///< what vkrt will not honour, one readable phrase each
};

/// The bytes of a bufferView (for images stored in the file), or an InputError.
using GltfViewBytes = std::function<std::vector<uint8_t>(uint32_t view, const std::string& where)>;

/// The materials of a glTF 2.0 document by file index, then glTF's default
/// material (for primitives without one) last. Throws InputError naming
/// `file` for a malformed material (non-finite or out-of-range factor, a
/// texture or image that is not there). An image file that `references`
/// refuses (outside the glTF's folder) is an InputError too.
std::vector<FileMaterial> readGltfMaterials(const nlohmann::json& doc, const std::filesystem::path& file,
                                            const ReferencePolicy& references, const GltfViewBytes& viewBytes);

/// The bytes of base64 text (RFC 4648, standard or URL alphabet, padding
/// optional); empty when the text is not base64.
std::vector<uint8_t> decodeBase64(std::string_view text);

/// A URI's file path (RFC 3986 percent-decoding: "my%20wood.png" is "my wood.png").
std::filesystem::path gltfUriPath(const std::string& uri);

/// The glTF JSON of a .gltf file or of a .glb's first chunk; throws InputError naming `file`.
std::string readGltfJson(const std::filesystem::path& file);

/// The most levels of arrays and objects the glTF JSON may nest (assimp's
/// rapidjson parses recursively and overflows its stack near 100,000).
constexpr size_t kMaxGltfJsonNesting = 1024;
/// The most levels of the node hierarchy (a root node is level 1): assimp
/// recurses once per level and crashes on a chain of 30,000 nodes.
constexpr uint32_t kMaxGltfNodeDepth = 1024;

/// The most mesh instances a glTF scene may place (nodes and
/// EXT_mesh_gpu_instancing copies): each is a 144-byte GPU record and a leaf
/// of the top-level BVH.
constexpr uint64_t kMaxGltfInstances = uint64_t(1) << 18;
/// The most nodes a glTF file may have, and the most its scene may reach (a
/// node listed twice among the scene's roots is reached twice, with its
/// subtree): each costs a walk step and, placing a mesh, an instance.
constexpr uint64_t kMaxGltfNodes = 65536;
/// The most triangles the meshes a glTF scene places may hold, each mesh
/// counted once (its instances share it), and the most a mesh object may
/// hold after its instances are flattened into one mesh (GltfReader.h).
/// Measured through `vkrt info` on lavapipe: an indexed mesh with normals
/// peaks at 1.55 GB for 8.4 M triangles (about 190 bytes a triangle to parse,
/// 64 bytes on the GPU before BVH nodes), a triangle soup with normals and
/// uvs at about 460 bytes a triangle. 8 Mi triangles are 288 MiB of triangle
/// storage: within every discrete GPU's maxStorageBufferRange (4 GiB), over
/// lavapipe's 128 MiB (3.7 M triangles, refused when the scene is uploaded,
/// naming the mesh).
constexpr uint64_t kMaxGltfTriangles = uint64_t(8) << 20;
/// The most bytes of accessor data the file's meshes, morph targets, skins
/// and animations may name, each reference counted (assimp copies an
/// accessor's data once per use) and an accessor without a bufferView
/// twice (assimp first makes its zeros: 600 bytes of JSON asked for 2.4 GB).
/// 8 Mi triangles of an indexed mesh with normals, uvs and tangents need
/// about 290 MB; the same as a soup of unshared vertices, 1.15 GB.
constexpr uint64_t kMaxGltfAccessorBytes = uint64_t(1) << 30;

/// Checks, before the reader (GltfReader.h) maps the file, what it would trust:
/// - every accessor lies inside its bufferView and every bufferView inside
///   its buffer's byteLength (assimp 5.2.5 copies accessor data without that
///   check: a heap overflow the fuzzer found);
/// - the JSON nests at most kMaxGltfJsonNesting levels, and the node
///   hierarchy is a set of trees (no cycle, at most one parent per node) at
///   most kMaxGltfNodeDepth levels deep;
/// - the file has, and its scene reaches, at most kMaxGltfNodes nodes, placing
///   meshes at most kMaxGltfInstances times; the placed meshes hold at most
///   kMaxGltfTriangles triangles, and
///   the accessors it uses at most kMaxGltfAccessorBytes bytes;
/// - every buffer and image file URI is one `references` allows.
/// Throws InputError naming `file` and the accessor, view, node, buffer or
/// image, or for JSON that cannot be parsed or repeats a key in an object
/// (which assimp's parser and ours would read differently). Fields of the
/// wrong type are left to assimp, which reports them.
void checkGltfBeforeImport(const std::filesystem::path& file, const ReferencePolicy& references);
/// The same checks, returning the parsed document (the one parse of its JSON).
nlohmann::json checkedGltfDocument(const std::filesystem::path& file, const ReferencePolicy& references);

} // namespace vkrt
