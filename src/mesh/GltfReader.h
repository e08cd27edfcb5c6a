#pragma once
// glTF 2.0 files, read once: the document (JSON, checked by
// checkGltfBeforeImport before anything trusts it), its buffers, every
// primitive of every mesh with all its attributes, the node tree of the
// chosen scene with exact double-precision transforms, and the file's
// materials. The one reader of glTF in vkrt: mesh objects of a TOML scene
// (loadMeshFile, which flattens the instances), glTF scenes (scene/GltfScene,
// which keeps them as instances sharing geometry) and the fuzzer all come
// through here.
//
// What vkrt reads (glTF 2.0 core):
// - accessors of every component type, normalized or not, interleaved
//   (byteStride), with or without a bufferView, sparse ones resolved;
// - primitives of modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN, indexed or
//   not; POINTS and LINES* are skipped with one warning per file;
// - attributes per primitive: POSITION, NORMAL, TANGENT, TEXCOORD_0 and _1,
//   COLOR_0 (float, normalized unsigned byte and short). A mesh mixes
//   primitives with and without an attribute: the missing ones get neutral
//   values (no normal: the face normal; no uv: (0, 0); no colour: white);
// - nodes: matrix or TRS, any size (nothing is rounded to identity), negative
//   scales (a mirrored instance's triangles keep their front side), meshes
//   referenced by several nodes and EXT_mesh_gpu_instancing as instances of
//   one mesh;
// - `scenes` and `scene` (GltfReadOptions::scene chooses another), cameras
//   and KHR_lights_punctual lights with the world transforms of their nodes,
//   in file order of the nodes;
// - extensionsRequired naming an extension vkrt does not implement is an
//   error, as the specification requires.
#include "mesh/MeshData.h"
#include "mesh/ReferencePolicy.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

/// One placement of a glTF mesh (a node, or one of a node's
/// EXT_mesh_gpu_instancing copies) with its world transform.
struct GltfInstance {
    uint32_t mesh = 0;     ///< index into GltfModel::meshes
    glm::dmat4 world{1.0}; ///< node world transform (instancing's TRS applied last)
    std::string nodeName;  ///< "" when the node has none
};

/// A camera or light and the world transform of the node that carries it.
struct GltfPlaced {
    uint32_t index = 0;   ///< into the file's `cameras`, or KHR_lights_punctual's `lights`
    uint32_t node = 0;    ///< the node carrying it
    std::string nodeName; ///< "" when the node has none
    glm::dmat4 world{1.0};
};

/// A glTF camera as the file defines it (checked: yfov in (0, pi),
/// aspectRatio > 0, xmag and ymag non-zero).
struct GltfCamera {
    std::string name;
    bool orthographic = false;
    double yfov = 0.0;                 ///< perspective: vertical field of view, radians
    std::optional<double> aspectRatio; ///< perspective: width / height, when given
    double xmag = 1.0, ymag = 1.0;     ///< orthographic: half the view's width and height
};

/// A KHR_lights_punctual light as the file defines it (checked: colour and
/// intensity >= 0, finite; 0 <= inner <= outer <= pi/2 for a spot).
struct GltfLight {
    std::string name;
    std::string type; ///< "point", "spot" or "directional"
    glm::dvec3 color{1.0};
    double intensity = 1.0;
    bool hasRange = false;
    double innerConeAngle = 0.0, outerConeAngle = 0.7853981633974483; ///< radians
};

/// What the command line chooses of a file.
struct GltfReadOptions {
    /// `--scene NAME|INDEX`: one of the file's `scenes`; unset: the file's `scene`, else scene 0.
    std::optional<std::string> scene;
    /// `--variant NAME|INDEX`: a KHR_materials_variants variant; unset: the primitives' own materials.
    std::optional<std::string> variant;
    MeshLoadOptions references;
};

/// A glTF file mapped to vkrt's terms.
struct GltfModel {
    std::filesystem::path file;
    /// One entry per glTF mesh (index = the file's mesh index): its triangle
    /// primitives as one MeshData whose triangleMaterials index `materials`
    /// below (MeshData::materials stays empty). A mesh without triangles has
    /// no triangles here and no instance.
    std::vector<MeshData> meshes;
    std::vector<std::string> meshNames; ///< the file's names, "" where it gives none
    /// The file's materials by file index, then glTF's default material (for
    /// primitives without one) last.
    std::vector<FileMaterial> materials;
    std::vector<GltfInstance> instances;
    std::vector<GltfPlaced> cameras; ///< in the order the scene's node walk meets them
    std::vector<GltfPlaced> lights;
    std::vector<GltfCamera> cameraDefinitions; ///< the file's `cameras`, by index
    std::vector<GltfLight> lightDefinitions;   ///< KHR_lights_punctual's `lights`, by index
    uint32_t sceneIndex = 0;                   ///< the scene read (0 when the file has none)
    std::string sceneName;                     ///< its name, "" when it has none
    /// What vkrt cannot honour, each once per file, in order (phrases without the file's name).
    std::vector<std::string> warnings;
    /// The buffer files it read (not data: URIs nor the .glb's own chunk).
    std::vector<std::filesystem::path> referencedFiles;
};

/// Reads `file` (.gltf or .glb). Throws InputError naming the file and the
/// accessor, primitive, node, buffer or scene that is wrong.
GltfModel readGltfModel(const std::filesystem::path& file, const GltfReadOptions& options = {});

/// Every instance of the model as one object-space mesh (loadMeshFile's
/// form: positions, normals and tangents transformed in double precision,
/// mirrored instances' triangles turned round, the materials the triangles
/// use copied into MeshData::materials). Throws InputError when the
/// instances hold more than kMaxGltfTriangles triangles (FileMaterials.h).
MeshData flattenGltfModel(GltfModel model);

/// The extensions vkrt implements (extensionsRequired may name only these).
const std::vector<std::string>& implementedGltfExtensions();

} // namespace vkrt
