#pragma once
// The files a parsed scene read besides itself, for the output checks of
// io/OutputPaths.h: the command line's and the Python module's alike.
#include "io/OutputPaths.h"
#include "scene/Scene.h"

#include <vector>

namespace vkrt {

/// The files a parsed scene read besides itself (meshes, textures, cube
/// faces, the environment map): no output of a command may replace one
/// (`-o sky/px.exr` must not overwrite one of its own faces).
std::vector<NamedFile> filesTheSceneRead(const Scene& scene);

} // namespace vkrt
