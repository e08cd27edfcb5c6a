#pragma once
// Loading the six faces of a scene's cubemap environment.
#include "io/Image.h"
#include "scene/Scene.h"

#include <array>

namespace vkrt {

/// Reads all six faces; throws InputError naming the scene location and the
/// face file when one is unreadable, not square, or differs in size.
std::array<Image, 6> loadCubemapFaces(const Cubemap& cubemap);

} // namespace vkrt
