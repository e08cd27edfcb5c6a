#pragma once
// The discrete distribution over cubemap texels that the path integrator
// samples the environment with (shaders/lib/environment.glsl).
#include "io/Image.h"

#include <array>
#include <vector>

namespace vkrt {

/// Cumulative probabilities, 6 N^2 + 1 entries from 0 to exactly 1, texel
/// order face-major then row-major. Texel weight: luminance times the texel's
/// solid angle (4 / (N^2 r^3) at its centre). A black environment gets a
/// uniform distribution (it is never worth sampling, but must stay valid).
std::vector<float> environmentCdf(const std::array<Image, 6>& faces);

} // namespace vkrt
