#pragma once
// What the readers of one scene file share besides the table they read: the
// scene being built and the caches that let records share what they load.
#include "scene/Scene.h"

#include <map>
#include <vector>

namespace vkrt {

class MeshGeometryCache; // mesh/MeshGeometry.h

/// One parse's state, handed to every kind's reader (scene/kinds/Kinds.h).
struct ParseContext {
    Scene& scene;
    /// Every texture the scene's materials load, one per (file, linear).
    TextureAtlas& textures;
    /// The mesh geometries loaded so far, so that instances of one file share one.
    MeshGeometryCache& meshes;
    /// The scene materials made from each geometry's file materials, so that instances share them.
    std::map<const MeshGeometry*, std::vector<uint32_t>> fileMaterials;
};

} // namespace vkrt
