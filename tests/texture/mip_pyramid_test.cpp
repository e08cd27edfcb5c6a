// Mip chains (src/texture/MipPyramid.h): sizes for any side, means kept at
// every level, and no shift of the image for odd sizes.
#include "texture/MipPyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace vkrt::test {
namespace {

double channelMean(const RgbaImage& image, int channel)
{
    double sum = 0.0;
    for (size_t i = 0; i < image.texelCount(); ++i) sum += image.rgba[i * 4 + channel];
    return sum / double(image.texelCount());
}

RgbaImage checkerboard(uint32_t width, uint32_t height)
{
    RgbaImage image(width, height);
    for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < width; ++x) {
            const float value = (x + y) % 2 ? 1.0f : 0.0f;
            float* texel = image.at(x, y);
            texel[0] = texel[1] = value;
            texel[2] = 0.25f;
            texel[3] = 1.0f - value;
        }
    }
    return image;
}

TEST(MipPyramid, LevelSizesHalveDownToOne)
{
    EXPECT_EQ(mipLevelCount(1, 1), 1u);
    EXPECT_EQ(mipLevelCount(2, 1), 2u);
    EXPECT_EQ(mipLevelCount(256, 256), 9u);
    EXPECT_EQ(mipLevelCount(5, 3), 3u);
    EXPECT_EQ(mipLevelCount(1, 16384), 15u);
    const std::vector<RgbaImage> pyramid = buildMipPyramid(checkerboard(13, 6));
    ASSERT_EQ(pyramid.size(), 4u);
    const uint32_t widths[] = {13, 6, 3, 1}, heights[] = {6, 3, 1, 1};
    for (size_t l = 0; l < pyramid.size(); ++l) {
        EXPECT_EQ(pyramid[l].width, widths[l]) << l;
        EXPECT_EQ(pyramid[l].height, heights[l]) << l;
        EXPECT_EQ(mipSize(13, uint32_t(l)), widths[l]);
        EXPECT_EQ(mipSize(6, uint32_t(l)), heights[l]);
    }
}

TEST(MipPyramid, CheckerboardMeanIsKeptAtEveryLevel)
{
    for (auto [w, h] : {std::pair{16u, 16u}, {17u, 16u}, {7u, 5u}, {1u, 9u}, {255u, 3u}, {6u, 6u}}) {
        const std::vector<RgbaImage> pyramid = buildMipPyramid(checkerboard(w, h));
        for (int c = 0; c < 4; ++c) {
            const double mean = channelMean(pyramid[0], c);
            for (const RgbaImage& level : pyramid)
                EXPECT_NEAR(channelMean(level, c), mean, 1e-6)
                    << w << "x" << h << " level " << level.width << "x" << level.height << " channel " << c;
        }
        // An even checkerboard averages to exactly 0.5 grey one level down.
        if (w % 2 == 0 && h % 2 == 0) {
            EXPECT_FLOAT_EQ(pyramid[1].at(0, 0)[0], 0.5f);
        }
    }
}

/// Length of [a0, a1) inside [b0, b1).
double overlap(double a0, double a1, double b0, double b1)
{
    return std::max(0.0, std::min(a1, b1) - std::max(a0, b0));
}

// Every level of odd, even and mixed sizes is the exact area average of level
// 0 over each texel's footprint (computed here by brute force in 2D).
TEST(MipPyramid, EveryLevelIsTheAreaAverageOfLevelZero)
{
    for (auto [w, h] : {std::pair{31u, 9u}, {100u, 3u}, {13u, 13u}, {7u, 1u}, {64u, 6u}}) {
        RgbaImage image(w, h);
        for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = float((i * 2654435761u >> 7) % 1000) / 999.0f;
        const std::vector<RgbaImage> pyramid = buildMipPyramid(image);
        for (size_t l = 1; l < pyramid.size(); ++l) {
            const RgbaImage& level = pyramid[l];
            const double sx = double(w) / level.width, sy = double(h) / level.height;
            for (uint32_t y = 0; y < level.height; ++y) {
                for (uint32_t x = 0; x < level.width; ++x) {
                    double expected[4] = {};
                    for (uint32_t j = 0; j < h; ++j)
                        for (uint32_t i = 0; i < w; ++i) {
                            const double area = overlap(x * sx, (x + 1) * sx, i, i + 1.0) *
                                                overlap(y * sy, (y + 1) * sy, j, j + 1.0) / (sx * sy);
                            for (int c = 0; c < 4; ++c) expected[c] += area * image.at(i, j)[c];
                        }
                    for (int c = 0; c < 4; ++c)
                        ASSERT_NEAR(level.at(x, y)[c], expected[c], 1e-5)
                            << w << "x" << h << " level " << l << " texel " << x << "," << y;
                }
            }
        }
    }
}

// So a ramp of texel-centre u stays that ramp in each level up to the
// staircase of level 0 (half a level-0 texel at most), exactly for powers of two.
TEST(MipPyramid, OddSizesDoNotShiftTheImage)
{
    for (uint32_t w : {3u, 5u, 7u, 13u, 31u, 100u, 64u}) {
        RgbaImage ramp(w, 3);
        for (uint32_t y = 0; y < 3; ++y)
            for (uint32_t x = 0; x < w; ++x) ramp.at(x, y)[0] = (x + 0.5f) / float(w); // u of the texel centre
        const bool powerOfTwo = (w & (w - 1)) == 0;
        for (const RgbaImage& level : buildMipPyramid(ramp))
            for (uint32_t x = 0; x < level.width; ++x)
                EXPECT_NEAR(level.at(x, 0)[0], (x + 0.5) / level.width, powerOfTwo ? 1e-6 : 0.5 / w)
                    << w << " level width " << level.width;
    }
}

// No shift as a whole: the pyramid of a mirrored image is the mirrored pyramid.
TEST(MipPyramid, FilterIsMirrorSymmetric)
{
    RgbaImage image(23, 11), mirrored(23, 11);
    for (uint32_t y = 0; y < 11; ++y)
        for (uint32_t x = 0; x < 23; ++x)
            for (int c = 0; c < 4; ++c)
                image.at(x, y)[c] = mirrored.at(22 - x, 10 - y)[c] = float((x * 7 + y * 13 + c * 5) % 17) / 16.0f;
    const std::vector<RgbaImage> a = buildMipPyramid(image), b = buildMipPyramid(mirrored);
    for (size_t l = 0; l < a.size(); ++l)
        for (uint32_t y = 0; y < a[l].height; ++y)
            for (uint32_t x = 0; x < a[l].width; ++x)
                for (int c = 0; c < 4; ++c)
                    EXPECT_NEAR(a[l].at(x, y)[c], b[l].at(a[l].width - 1 - x, a[l].height - 1 - y)[c], 1e-6);
}

TEST(MipPyramid, ConstantStaysConstant)
{
    RgbaImage image(11, 7);
    for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = 0.3f + 0.1f * float(i % 4);
    for (const RgbaImage& level : buildMipPyramid(image))
        for (size_t i = 0; i < level.rgba.size(); ++i) EXPECT_NEAR(level.rgba[i], 0.3f + 0.1f * float(i % 4), 1e-6);
}

// The odd 3-tap filter's weights (k - i, k, i + 1) / (2k + 1): 5 -> 2 texels.
TEST(MipPyramid, OddFilterWeightsAreTheAreaFractions)
{
    RgbaImage image(5, 1);
    for (uint32_t x = 0; x < 5; ++x) image.at(x, 0)[0] = float(1 << x); // 1, 2, 4, 8, 16
    const RgbaImage half = mipLevel(image, 1);
    ASSERT_EQ(half.width, 2u);
    EXPECT_FLOAT_EQ(half.at(0, 0)[0], (2 * 1 + 2 * 2 + 1 * 4) / 5.0f);
    EXPECT_FLOAT_EQ(half.at(1, 0)[0], (1 * 4 + 2 * 8 + 2 * 16) / 5.0f);
}

} // namespace
} // namespace vkrt::test
