#pragma once
// The Vulkan cube map convention (Vulkan spec, "Cube Map Face Selection"):
// which direction each texel of each face stands for. Face order +x, -x,
// +y, -y, +z, -z; texel (s, t) in [0,1]^2 with t growing downwards in the
// stored image (row 0 first).
#include <glm/glm.hpp>

namespace vkrt {

/// Unit direction through point (s, t) of `face`.
inline glm::dvec3 cubeFaceDirection(int face, double s, double t)
{
    double sc = 2.0 * s - 1.0, tc = 2.0 * t - 1.0;
    glm::dvec3 d;
    switch (face) {
    case 0: d = {1.0, -tc, -sc}; break;   // +x: sc = -z, tc = -y
    case 1: d = {-1.0, -tc, sc}; break;   // -x: sc = +z, tc = -y
    case 2: d = {sc, 1.0, tc}; break;     // +y: sc = +x, tc = +z
    case 3: d = {sc, -1.0, -tc}; break;   // -y: sc = +x, tc = -z
    case 4: d = {sc, -tc, 1.0}; break;    // +z: sc = +x, tc = -y
    default: d = {-sc, -tc, -1.0}; break; // -z: sc = -x, tc = -y
    }
    return glm::normalize(d);
}

} // namespace vkrt
