// What `vkrt render --vector-width` decides (gpu/VectorWidth.h): the width
// lavapipe runs at, read from its device name; Mesa's version; auto's measured
// rule (512 bits only on Mesa >= 26, only without meshes and without the
// driver's ray queries, only on an AVX-512 CPU; a user's
// $LP_NATIVE_VECTOR_WIDTH stands); and the explicit choices it refuses.
#include "gpu/VectorWidth.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

namespace vkrt::test {
namespace {

DeviceInfo lavapipe(const std::string& name, const std::string& driver)
{
    DeviceInfo device;
    device.name = name;
    device.driver = driver;
    device.driverId = vk::DriverId::eMesaLlvmpipe;
    device.type = vk::PhysicalDeviceType::eCpu;
    return device;
}

const DeviceInfo kMesa26 =
    lavapipe("llvmpipe (LLVM 19.1.7, 256 bits)", "llvmpipe: Mesa 26.1.6-1~bpo13+1 (LLVM 19.1.7)");
const DeviceInfo kMesa25 =
    lavapipe("llvmpipe (LLVM 15.0.6, 512 bits)", "llvmpipe: Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)");

VectorWidthFacts factsOf(const DeviceInfo& device)
{
    VectorWidthFacts facts;
    facts.runningBits = lavapipeVectorBits(device);
    facts.mesa = mesaVersion(device);
    facts.avx512 = true;
    return facts;
}

TEST(VectorWidth, ReadsTheRunningWidthAndMesasVersionFromTheDevice)
{
    EXPECT_EQ(lavapipeVectorBits(kMesa26), 256);
    EXPECT_EQ(lavapipeVectorBits(kMesa25), 512);
    EXPECT_EQ(mesaVersion(kMesa26), std::make_pair(26, 1));
    EXPECT_EQ(mesaVersion(kMesa25), std::make_pair(25, 0));
    DeviceInfo gpu;
    gpu.name = "NVIDIA H100 80GB HBM3 (256 bits)"; // a width in the name is not lavapipe's
    gpu.driver = "NVIDIA 560.35";
    gpu.driverId = vk::DriverId::eNvidiaProprietary;
    EXPECT_EQ(lavapipeVectorBits(gpu), std::nullopt);
    EXPECT_EQ(mesaVersion(gpu), std::nullopt);
}

TEST(VectorWidth, AutoPicks512OnlyWhereItMeasuredFaster)
{
    VectorWidthFacts facts = factsOf(kMesa26);
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, facts), 512);
    VectorWidthFacts meshes = facts;
    meshes.meshes = true; // 0.78-0.83x on Mesa 26
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, meshes), 256);
    VectorWidthFacts rayQueries = facts;
    rayQueries.driverAccel = true; // Mesa 26 aborts compiling it at 512 bits
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, rayQueries), 256);
    VectorWidthFacts noAvx512 = facts;
    noAvx512.avx512 = false;
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, noAvx512), 256);
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, factsOf(kMesa25)), 256); // 0.74-0.98x on Mesa 25
    VectorWidthFacts userSet = facts;
    userSet.widthFromEnvironment = true;
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, userSet), std::nullopt);
    VectorWidthFacts userSet512 = userSet;
    userSet512.runningBits = 512;
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, userSet512), std::nullopt);
    userSet512.driverAccel = true; // into lavapipe's abort: refused
    EXPECT_THROW(chooseVectorBits(VectorWidthChoice::Auto, userSet512), InputError);
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Auto, VectorWidthFacts{}), std::nullopt); // not lavapipe
}

/// The InputError an explicit choice throws ("" when it is accepted).
std::string refusal(VectorWidthChoice choice, const VectorWidthFacts& facts)
{
    try {
        chooseVectorBits(choice, facts);
    } catch (const InputError& error) {
        return error.what();
    }
    return "";
}

TEST(VectorWidth, AnExplicitWidthIsKeptOrRefusedWithTheReason)
{
    VectorWidthFacts facts = factsOf(kMesa26);
    facts.meshes = true;
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Bits512, facts), 512); // slower, but asked for
    EXPECT_EQ(chooseVectorBits(VectorWidthChoice::Bits256, factsOf(kMesa25)), 256);
    EXPECT_NE(refusal(VectorWidthChoice::Bits512, VectorWidthFacts{}).find("not lavapipe"), std::string::npos);
    EXPECT_NE(refusal(VectorWidthChoice::Bits256, VectorWidthFacts{}).find("--vector-width 256"), std::string::npos);
    VectorWidthFacts noAvx512 = facts;
    noAvx512.avx512 = false;
    EXPECT_NE(refusal(VectorWidthChoice::Bits512, noAvx512).find("AVX-512"), std::string::npos);
    VectorWidthFacts rayQueries = facts;
    rayQueries.driverAccel = true;
    EXPECT_NE(refusal(VectorWidthChoice::Bits512, rayQueries).find("--accel own"), std::string::npos);
    VectorWidthFacts rayQueries25 = factsOf(kMesa25);
    rayQueries25.driverAccel = true; // Mesa 25 compiles and runs it at 512 bits
    EXPECT_EQ(refusal(VectorWidthChoice::Bits512, rayQueries25), "");
}

TEST(VectorWidth, EachWidthHasItsOwnMesaCacheBesideTheUsersOne)
{
    const char* old = std::getenv("MESA_SHADER_CACHE_DIR");
    const std::string saved = old ? old : "";
    setenv("MESA_SHADER_CACHE_DIR", "/var/cache/mesa", 1);
    EXPECT_EQ(mesaCacheDirForWidth(512), "/var/cache/mesa/vkrt-lavapipe-512-bit");
    EXPECT_NE(mesaCacheDirForWidth(512), mesaCacheDirForWidth(256));
    if (old) setenv("MESA_SHADER_CACHE_DIR", saved.c_str(), 1);
    else unsetenv("MESA_SHADER_CACHE_DIR");
}

} // namespace
} // namespace vkrt::test
