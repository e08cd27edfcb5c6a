// The named conductor table: lookups, names for did-you-mean, and physically sensible reflectances.
#include "material/Fresnel.h"
#include "material/Metals.h"

#include <algorithm>
#include <gtest/gtest.h>

namespace vkrt {
namespace {

double normalReflectance(const Metal& metal, int channel)
{
    return fresnelConductor(1.0, metal.eta[channel], metal.k[channel]);
}

TEST(Metals, KnowsTheMetalsTheIssueNames)
{
    for (const char* name : {"Au", "Ag", "Cu", "Al", "Cr"}) {
        const Metal* metal = findMetal(name);
        ASSERT_NE(metal, nullptr) << name;
        EXPECT_EQ(metal->name, name);
    }
    EXPECT_EQ(findMetal("Gold"), nullptr);
    EXPECT_EQ(findMetal("au"), nullptr);
    EXPECT_EQ(findMetal(""), nullptr);
}

TEST(Metals, NamesListEveryEntryOnce)
{
    auto names = metalNames();
    EXPECT_GE(names.size(), 5u);
    for (const auto& name : names) {
        EXPECT_NE(findMetal(name), nullptr) << name;
        EXPECT_EQ(std::count(names.begin(), names.end(), name), 1) << name;
    }
}

TEST(Metals, ReflectancesLookLikeTheMetals)
{
    const Metal& gold = *findMetal("Au");
    const Metal& copper = *findMetal("Cu");
    const Metal& silver = *findMetal("Ag");
    const Metal& aluminium = *findMetal("Al");
    // Gold and copper are warm: red > green > blue at normal incidence.
    EXPECT_GT(normalReflectance(gold, 0), normalReflectance(gold, 1));
    EXPECT_GT(normalReflectance(gold, 1), normalReflectance(gold, 2));
    EXPECT_GT(normalReflectance(copper, 0), normalReflectance(copper, 2));
    // Silver and aluminium are bright and nearly neutral (Ag ~0.95-0.98, Al ~0.91-0.93 in the visible).
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(normalReflectance(silver, c), 0.9);
        EXPECT_GT(normalReflectance(aluminium, c), 0.88);
    }
    // Gold's red reflectance is ~0.95 at 650 nm (Palik).
    EXPECT_NEAR(normalReflectance(gold, 0), 0.95, 0.03);
}

TEST(Metals, NoneIsAPerfectMirror)
{
    const Metal& none = *findMetal("none");
    for (double cosI : {1.0, 0.7, 0.2, 1e-3, 0.0})
        EXPECT_NEAR(fresnelConductor(cosI, none.eta[0], none.k[0]), 1.0, 1e-12) << cosI;
}

} // namespace
} // namespace vkrt
