// The lat-long map's sampling distribution (render/EnvironmentSampling.h):
// CDFs that are valid (non-decreasing from 0 to 1), weights where the map
// has light, and a grid that stays bounded for the largest maps.
#include "render/Environment.h"
#include "render/EnvironmentSampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <span>

namespace vkrt {
namespace {

void expectValidCdf(const float* cdf, size_t entries)
{
    EXPECT_EQ(cdf[0], 0.0f);
    EXPECT_EQ(cdf[entries - 1], 1.0f);
    for (size_t i = 1; i < entries; ++i) EXPECT_GE(cdf[i], cdf[i - 1]) << i;
}

TEST(LatLongDistribution, OneBrightTexelCarriesItsFourBilinearCells)
{
    Image map(16, 9);
    std::fill(map.rgb.begin(), map.rgb.end(), 1e-3f);
    float* sun = map.at(5, 3);
    sun[0] = sun[1] = sun[2] = 1e4f;
    const LatLongDistribution d = latLongDistribution(map);
    ASSERT_EQ(d.block, 1u);
    ASSERT_EQ(d.columns, 16u);
    ASSERT_EQ(d.rows, 8u);
    ASSERT_EQ(d.cdf.size(), size_t(9 + 8 * 17));
    expectValidCdf(d.cdf.data(), 9);
    // Texel (5, 3) is a corner of bilinear cells i in {4, 5}, j in {2, 3}.
    auto cellProbability = [&](uint32_t i, uint32_t j) {
        const float* row = d.cdf.data() + 9 + j * 17;
        return double(d.cdf[j + 1] - d.cdf[j]) * (row[i + 1] - row[i]);
    };
    double sunCells = 0.0;
    for (uint32_t j = 0; j < 8; ++j) {
        expectValidCdf(d.cdf.data() + 9 + j * 17, 17);
        for (uint32_t i = 0; i < 16; ++i) {
            EXPECT_GT(cellProbability(i, j), 0.0) << "every cell with light must be reachable";
            if ((i == 4 || i == 5) && (j == 2 || j == 3)) sunCells += cellProbability(i, j);
        }
    }
    EXPECT_GT(sunCells, 0.999);
}

TEST(LatLongDistribution, ColumnsWrapAroundTheSeam)
{
    Image map(8, 5);
    float* texel = map.at(0, 2); // its cells are i = 7 (with column 0 as its right corner) and i = 0
    texel[1] = 1.0f;
    const LatLongDistribution d = latLongDistribution(map);
    const float* row = d.cdf.data() + 5 + 2 * 9;
    EXPECT_GT(row[8] - row[7], 0.4f);
    EXPECT_GT(row[1] - row[0], 0.4f);
}

TEST(LatLongDistribution, ABlackMapIsSampledUniformly)
{
    const LatLongDistribution d = latLongDistribution(Image(4, 3));
    EXPECT_FLOAT_EQ(d.cdf[1], 0.5f);
    EXPECT_FLOAT_EQ(d.cdf[3 + 1], 0.25f);
}

TEST(ConstantEnvironment, IsOneWhoseTexelsAreAllEqual)
{
    Image map(6, 4);
    for (size_t i = 0; i < map.rgb.size(); i += 3) {
        map.rgb[i] = 0.25f;
        map.rgb[i + 1] = 2.0f;
        map.rgb[i + 2] = 1.0f;
    }
    EXPECT_TRUE(isConstantEnvironment(std::span(&map, 1)));
    map.at(5, 3)[1] = 2.0001f; // the last texel's green alone
    EXPECT_FALSE(isConstantEnvironment(std::span(&map, 1)));

    std::array<Image, 6> faces;
    faces.fill(Image(2, 2));
    for (Image& face : faces) std::fill(face.rgb.begin(), face.rgb.end(), 0.5f);
    EXPECT_TRUE(isConstantEnvironment(faces));
    faces[4].rgb[0] = 0.0f; // one face's first red
    EXPECT_FALSE(isConstantEnvironment(faces));
}

TEST(LatLongDistribution, LargeMapsGroupCellsIntoBlocks)
{
    // 4097 x 2050 has 4097 x 2049 bilinear cells, just over kMaxLatLongCells:
    // blocks of 2 x 2, the last column and row of blocks holding one cell across.
    Image map(4097, 2050);
    std::fill(map.rgb.begin(), map.rgb.end(), 1.0f);
    const LatLongDistribution d = latLongDistribution(map);
    EXPECT_EQ(d.block, 2u);
    EXPECT_EQ(d.columns, 2049u);
    EXPECT_EQ(d.rows, 1025u);
    EXPECT_LE(uint64_t(d.columns) * d.rows, kMaxLatLongCells);
    ASSERT_EQ(d.cdf.size(), size_t(1026) + size_t(1025) * 2050);
    // A constant map: the last column of blocks holds half a block's weight.
    const float* row = d.cdf.data() + 1026 + 512 * 2050;
    EXPECT_NEAR((row[2049] - row[2048]) / (row[1] - row[0]), 0.5, 1e-3);
}

// The studio environment, a glTF scene's default (docs/scene-format.md): a
// 2:1 grey map, 1 at the zenith, 0.6 at the horizon, 0.25 for the ground,
// never brighter further down; a white surface facing up sees more than the
// horizon behind it, one facing down less.
TEST(StudioEnvironment, IsTheDocumentedNeutralGradient)
{
    const Image map = studioEnvironment();
    ASSERT_EQ(map.width, 2 * map.height);
    const auto at = [&](uint32_t row, uint32_t column, int c) {
        return map.rgb[(size_t(row) * map.width + column) * 3 + c];
    };
    const double pi = 3.14159265358979323846;
    for (uint32_t j = 0; j < map.height; ++j) {
        const double y = std::cos(pi * (j + 0.5) / map.height);
        for (uint32_t i : {0u, map.width / 3, map.width - 1})
            for (int c = 0; c < 3; ++c) ASSERT_EQ(at(j, i, c), at(j, 0, 0)) << "row " << j << " is not one grey";
        if (j > 0) {
            EXPECT_LE(at(j, 0, 0), at(j - 1, 0, 0)) << "row " << j;
        }
        if (y >= 0.0) {
            EXPECT_NEAR(at(j, 0, 0), 0.6 + 0.4 * y, 1e-6) << "row " << j;
        }
        if (y < -std::sin(15.0 * pi / 180.0)) {
            EXPECT_FLOAT_EQ(at(j, 0, 0), 0.25f) << "row " << j;
        }
    }
    EXPECT_NEAR(at(0, 0, 0), 1.0, 1e-3);
    EXPECT_NEAR(at(map.height / 2 - 1, 0, 0), 0.6, 0.02);
    // Cosine-weighted mean radiance seen by a surface facing up, and down (the irradiance over pi).
    double up = 0.0, down = 0.0, upWeight = 0.0, downWeight = 0.0;
    for (uint32_t j = 0; j < map.height; ++j) {
        const double theta = pi * (j + 0.5) / map.height, y = std::cos(theta), area = std::sin(theta);
        (y > 0.0 ? up : down) += at(j, 0, 0) * std::abs(y) * area;
        (y > 0.0 ? upWeight : downWeight) += std::abs(y) * area;
    }
    EXPECT_GT(up / upWeight, 0.8);      // brighter than the horizon's 0.6 behind a model
    EXPECT_LT(down / downWeight, 0.35); // darker
}

} // namespace
} // namespace vkrt
