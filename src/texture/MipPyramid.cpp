#include "texture/MipPyramid.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace vkrt {

uint32_t mipSize(uint32_t size, uint32_t level)
{
    return level >= 32 ? 1u : std::max(1u, size >> level);
}

uint32_t mipLevelCount(uint32_t width, uint32_t height)
{
    return uint32_t(std::bit_width(std::max({width, height, 1u})));
}

namespace {

/// One output texel's input texels and their weights along one side.
struct Taps {
    uint32_t first = 0;
    std::vector<double> weights;
};

/// Output texel i of `outSize` covers [i, i + 1) * inSize / outSize of the
/// input; each input texel weighs the length it has in that interval.
Taps boxTaps(uint32_t inSize, uint32_t outSize, uint32_t i)
{
    const double scale = double(inSize) / double(outSize);
    const double begin = i * scale, end = (i + 1) * scale;
    Taps taps;
    taps.first = uint32_t(std::floor(begin));
    const uint32_t last = std::min(inSize, uint32_t(std::ceil(end)));
    for (uint32_t j = taps.first; j < last; ++j)
        taps.weights.push_back((std::min(end, j + 1.0) - std::max(begin, double(j))) / scale);
    return taps;
}

/// Box-resamples along x (horizontal = true) or y to `outSize`, leaving the other side.
RgbaImage resampleSide(const RgbaImage& in, uint32_t outSize, bool horizontal)
{
    const uint32_t inSize = horizontal ? in.width : in.height;
    if (inSize == outSize) return in;
    RgbaImage out(horizontal ? outSize : in.width, horizontal ? in.height : outSize);
    for (uint32_t o = 0; o < outSize; ++o) {
        const Taps taps = boxTaps(inSize, outSize, o);
        const uint32_t others = horizontal ? in.height : in.width;
        for (uint32_t k = 0; k < others; ++k) {
            double sum[4] = {};
            for (size_t t = 0; t < taps.weights.size(); ++t) {
                const uint32_t i = taps.first + uint32_t(t);
                const float* texel = horizontal ? in.at(i, k) : in.at(k, i);
                for (int c = 0; c < 4; ++c) sum[c] += taps.weights[t] * texel[c];
            }
            float* result = horizontal ? out.at(o, k) : out.at(k, o);
            for (int c = 0; c < 4; ++c) result[c] = float(sum[c]);
        }
    }
    return out;
}

RgbaImage resample(const RgbaImage& in, uint32_t width, uint32_t height)
{
    return resampleSide(resampleSide(in, width, true), height, false);
}

} // namespace

RgbaImage mipLevel(const RgbaImage& level0, uint32_t level)
{
    return resample(level0, mipSize(level0.width, level), mipSize(level0.height, level));
}

std::vector<RgbaImage> buildMipPyramid(RgbaImage level0)
{
    const uint32_t levels = mipLevelCount(level0.width, level0.height);
    std::vector<RgbaImage> pyramid;
    pyramid.reserve(levels);
    pyramid.push_back(std::move(level0));
    for (uint32_t level = 1; level < levels; ++level) {
        const uint32_t width = mipSize(pyramid[0].width, level), height = mipSize(pyramid[0].height, level);
        size_t source = level - 1;
        while (source > 0 && (pyramid[source].width % width != 0 || pyramid[source].height % height != 0)) --source;
        pyramid.push_back(resample(pyramid[source], width, height));
    }
    return pyramid;
}

} // namespace vkrt
