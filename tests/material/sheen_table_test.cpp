// The sheen albedo table (src/material/Sheen.h), computed at the start-up of
// every scene with sheen: its quadrature takes what does not change along a
// loop out of it, and must still give the sum of sheenBrdf at every node bit
// for bit, so that the optimisation changes no image.
#include "material/Sheen.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <vector>

namespace vkrt::test {
namespace {

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
            const double direct = sheenDirectionalAlbedoBrdfByBrdf(mu, roughness);
            EXPECT_EQ(std::bit_cast<uint64_t>(fast), std::bit_cast<uint64_t>(direct))
                << "mu " << mu << " roughness " << roughness << ": " << fast << " against " << direct;
            ++compared;
        }
    for (double mu : {1e-6, 0.37, 0.999999})
        EXPECT_EQ(std::bit_cast<uint64_t>(sheenDirectionalAlbedo(mu, 0.42)),
                  std::bit_cast<uint64_t>(sheenDirectionalAlbedoBrdfByBrdf(mu, 0.42)))
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
