#pragma once
// Loading the six faces of a scene's cubemap environment.
#include "io/Image.h"
#include "scene/Scene.h"

#include <array>
#include <cstdint>

namespace vkrt {

/// Largest cube face side (vkrt-make-sky's --size maximum): six faces of it
/// take 1.2 GB as float RGB, and as much again for sampling and upload.
constexpr uint32_t kMaxCubeFaceSide = 4096;

/// Reads all six faces; throws InputError naming the scene location and the
/// face file when one is unreadable, not square, larger than
/// kMaxCubeFaceSide, or differs in size. Sizes come from all six headers
/// before any face is decoded.
std::array<Image, 6> loadCubemapFaces(const Cubemap& cubemap);

} // namespace vkrt
