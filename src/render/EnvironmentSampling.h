#pragma once
// The distributions the environment maps are importance-sampled with
// (shaders/lib/environment.glsl): over a cubemap's texels (path integrator)
// and over a lat-long map's bilinear cells (both integrators).
#include "io/Image.h"

#include <array>
#include <span>
#include <vector>

namespace vkrt {

/// Cumulative probabilities, 6 N^2 + 1 entries from 0 to exactly 1, texel
/// order face-major then row-major. Texel weight: luminance times the texel's
/// solid angle (4 / (N^2 r^3) at its centre). A black environment gets a
/// uniform distribution (it is never worth sampling, but must stay valid).
std::vector<float> environmentCdf(const std::array<Image, 6>& faces);

/// The lat-long map's sampling distribution (shaders/lib/environment.glsl):
/// a grid over (s, v), s = u - 0.5 / W (mod 1), so that its lines fall on
/// texel centres and bilinear cell (i, j), between texels i, i + 1 (mod W)
/// and rows j, j + 1, spans s in [i, i + 1) / W, v in [j, j + 1) / (H - 1).
/// Grid cell (a, b) holds the bilinear cells i in [aB, aB + B), j in [bB,
/// bB + B) that exist, B = `block`, the smallest power of two that keeps the
/// grid within kMaxLatLongCells. A cell's weight is the sum over its
/// bilinear cells of their corners' mean luminance times sin(theta) at their
/// centre: positive wherever the map is, so sampling stays unbiased.
struct LatLongDistribution {
    uint32_t columns = 0, rows = 0, block = 1;
    /// rows + 1 marginal entries from 0 to 1, then per row its columns + 1
    /// conditional entries from 0 to 1.
    std::vector<float> cdf;
};

/// Whether every texel of the images has the same RGB (one image: a lat-long
/// map; six: a cubemap). Such an environment's light samples follow the
/// cosine lobe about the shading normal rather than its own distribution,
/// uniform over the sphere (RENDER_FLAG_CONSTANT_ENVIRONMENT, docs/performance.md).
bool isConstantEnvironment(std::span<const Image> images);

/// 8 Mi cells: a 4096 x 2049 map at full resolution, 32 MiB of CDF.
constexpr uint64_t kMaxLatLongCells = uint64_t(1) << 23;

/// `map` is at least 2 x 2 texels, finite and non-negative.
LatLongDistribution latLongDistribution(const Image& map);

} // namespace vkrt
