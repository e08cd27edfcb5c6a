// The sheen albedo table (src/material/Sheen.h), computed at the start-up of
// every scene with sheen: its quadrature takes what does not change along a
// loop out of it, and must still give the sum of sheenBrdf at every node bit
// for bit, so that the optimisation changes no image.
#include "material/Sheen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace vkrt::test {
namespace {

/// The quadrature as it was written before: sheenBrdf at every node, every
/// factor computed there (3.8x slower: 0.87-0.94 s for the table on one core).
double albedoBrdfByBrdf(double mu, double roughness)
{
    const double alpha = sheenAlpha(roughness);
    const double sinO = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    constexpr int kT = 64, kPhi = 32;
    double sum = 0.0;
    for (int a = 0; a < kT; ++a) {
        const double t = (a + 0.5) / kT;
        const double cosI = t * t, sinI = std::sqrt(std::max(0.0, 1.0 - cosI * cosI));
        double ring = 0.0;
        for (int b = 0; b < kPhi; ++b) {
            const double phi = std::numbers::pi * (b + 0.5) / kPhi;
            const double hx = sinO + sinI * std::cos(phi), hy = sinI * std::sin(phi), hz = mu + cosI;
            const double cosH = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
            ring += sheenBrdf(mu, cosI, cosH, alpha);
        }
        sum += ring * cosI * 2.0 * t;
    }
    return sum * (1.0 / kT) * (2.0 * std::numbers::pi / kPhi);
}

TEST(SheenTable, QuadratureEqualsTheSumOfTheBrdfBitForBit)
{
    // Every fifth row and column of the table's nodes (its cosine and
    // roughness, as sheenAlbedoTable spaces them), its last ones and cosines
    // outside the table.
    const unsigned side = kSheenTableSide;
    std::vector<unsigned> nodes;
    for (unsigned k = 0; k < side; k += 5) nodes.push_back(k);
    nodes.push_back(side - 1);
    int compared = 0;
    for (unsigned j : nodes)
        for (unsigned i : nodes) {
            const double s = double(i) / (side - 1);
            const double mu = std::max(s * s, 1e-4), roughness = double(j) / (side - 1);
            const double fast = sheenDirectionalAlbedo(mu, roughness);
            const double direct = albedoBrdfByBrdf(mu, roughness);
            EXPECT_EQ(std::bit_cast<uint64_t>(fast), std::bit_cast<uint64_t>(direct))
                << "mu " << mu << " roughness " << roughness << ": " << fast << " against " << direct;
            ++compared;
        }
    for (double mu : {1e-6, 0.37, 0.999999})
        EXPECT_EQ(std::bit_cast<uint64_t>(sheenDirectionalAlbedo(mu, 0.42)),
                  std::bit_cast<uint64_t>(albedoBrdfByBrdf(mu, 0.42)))
            << "mu " << mu;
    EXPECT_EQ(compared, 14 * 14);
}

TEST(SheenTable, EntriesAreTheQuadratureAtTheirNodes)
{
    const std::vector<float>& table = sheenAlbedoTable();
    const unsigned side = kSheenTableSide;
    ASSERT_EQ(table.size(), size_t(side) * side);
    for (unsigned j : {0u, 17u, side - 1})
        for (unsigned i : {0u, 1u, 40u, side - 1}) {
            const double s = double(i) / (side - 1);
            const double mu = std::max(s * s, 1e-4);
            EXPECT_EQ(table[size_t(j) * side + i], float(sheenDirectionalAlbedo(mu, double(j) / (side - 1))))
                << "row " << j << " column " << i;
        }
}

} // namespace
} // namespace vkrt::test
