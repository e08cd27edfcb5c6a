#pragma once
// glTF 2.0's alphaMode, as file materials read it (mesh/FileMaterials.h) and
// scene materials keep it (scene/Scene.h: Material); the values are the
// kernel's ALPHA_MODE_* (shared/SceneTypes.h, lib/alpha.glsl).
#include "shared/SceneTypes.h"

#include <cstdint>

namespace vkrt {

/// OPAQUE: always a surface; MASK: a surface where alpha >= alphaCutoff;
/// BLEND: a surface with probability alpha (stochastic transparency).
enum class AlphaMode : uint32_t {
    Opaque = gpu::ALPHA_MODE_OPAQUE,
    Mask = gpu::ALPHA_MODE_MASK,
    Blend = gpu::ALPHA_MODE_BLEND,
};

} // namespace vkrt
