#pragma once
// Loading a scene's environment: the six faces of a cubemap, or a lat-long map.
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

/// A lat-long map's sides: at least 2 x 2 texels (its bilinear cells need
/// two rows), at most 16384 wide (Vulkan's guaranteed 2D image side is
/// smaller; lavapipe's and desktop GPUs' are 16384) and ImageLimits' pixels.
constexpr uint32_t kMaxLatLongSide = 16384;

/// The built-in studio environment, a glTF scene without lights' default
/// (docs/scene-format.md): a neutral grey lat-long map, 256 x 128, brightest
/// at the zenith (radiance 1), 0.6 at the horizon and 0.25 below it (a
/// ground), the two joined over the 15 degrees under the horizon. A white
/// model stands out against it: its top is lit brighter than the horizon
/// behind it, its underside darker.
Image studioEnvironment();

/// Reads the scene's lat-long map (.exr or .hdr) times its scale (the
/// studio's when map.studio, scaled as well); throws
/// InputError naming the scene location and the file when it cannot be
/// read, is too small or too large (from its header, before decoding), or
/// holds (or scales to) a negative or non-finite value.
Image loadEnvironmentMap(const EnvironmentMap& map);

} // namespace vkrt
