// How the kernels read the scene's buffers (KernelVariant::sceneAddresses,
// lib/scene_buffers.glsl): through the buffers' device addresses or through
// their descriptors. Only the load instructions differ, so the sums, and so
// the images, their variance and the AOVs, are the same bit for bit.
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <filesystem>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class SceneReadsTest : public GpuTest {};

struct Rendered {
    Image mean, variance;
    AovImages aovs;
    bool addresses = false;
};

Rendered render(const std::string& relative, SceneReads reads, bool storageScene)
{
    Scene scene = parseSceneFile((fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / relative).string());
    scene.camera.width = 24;
    scene.camera.height = 16;
    RenderOptions options;
    options.seed = 5;
    options.sceneReads = reads;
    options.storageScene = storageScene;
    options.variance = true;
    options.aov = true;
    options.cacheDirectory = testCacheDir();
    Renderer renderer(gpu(), scene, options);
    renderer.warmUp();
    renderer.renderFrames(9);
    return {renderer.mean(), renderer.varianceOfMean(), renderer.aovs(), renderer.variant().sceneAddresses};
}

// Every read-only buffer kind: textures, mesh BVH, triangles, normals, uvs
// and tangents (textured), the environment's distribution (environment-hdri),
// the kinds' arrays and the materials as storage buffers (lights, glass on a
// mesh), the emitters and the top-level BVH.
TEST_F(SceneReadsTest, DeviceAddressesGiveTheDescriptorsImagesBitForBit)
{
    if (!gpu().deviceInfo().bufferDeviceAddress)
        GTEST_SKIP() << gpu().deviceInfo().name << " lacks the bufferDeviceAddress feature";
    for (const char* relative : {"validation/textured.toml", "validation/environment-hdri.toml",
                                 "validation/lights.toml", "validation/mesh-bunny-glass.toml"}) {
        Rendered address = render(relative, SceneReads::Address, true);
        Rendered descriptor = render(relative, SceneReads::Descriptor, true);
        ASSERT_TRUE(address.addresses);
        ASSERT_FALSE(descriptor.addresses);
        EXPECT_EQ(address.mean.rgb, descriptor.mean.rgb) << relative;
        EXPECT_EQ(address.variance.rgb, descriptor.variance.rgb) << relative;
        EXPECT_EQ(address.aovs.albedo.rgb, descriptor.aovs.albedo.rgb) << relative;
        EXPECT_EQ(address.aovs.normal.rgb, descriptor.aovs.normal.rgb) << relative;
        EXPECT_EQ(address.aovs.depth, descriptor.aovs.depth) << relative;
    }
    // The uniform-scene variant keeps its arrays in uniform blocks; the mesh buffers still go through addresses.
    Rendered address = render("validation/mesh-smooth.toml", SceneReads::Address, false);
    Rendered descriptor = render("validation/mesh-smooth.toml", SceneReads::Descriptor, false);
    EXPECT_EQ(address.mean.rgb, descriptor.mean.rgb);
}

DeviceInfo lavapipe(const std::string& mesa, bool bufferDeviceAddress)
{
    DeviceInfo device;
    device.name = "llvmpipe (LLVM 19.1.7, 256 bits)";
    device.driverId = vk::DriverId::eMesaLlvmpipe;
    device.driver = "llvmpipe: Mesa " + mesa + " (LLVM 19.1.7)";
    device.bufferDeviceAddress = bufferDeviceAddress;
    return device;
}

// Measured (docs/performance.md, "Staged kernels"): addresses compile much
// faster on Mesa 25 and no faster on Mesa 26; other devices keep descriptors.
TEST(SceneReadsRule, AddressesWhereTheyWereMeasuredToPay)
{
    EXPECT_TRUE(sceneAddressesPay(lavapipe("25.0.7", true)));
    EXPECT_TRUE(sceneAddressesPay(lavapipe("22.3.6", true)));
    EXPECT_FALSE(sceneAddressesPay(lavapipe("25.0.7", false)));
    EXPECT_FALSE(sceneAddressesPay(lavapipe("26.1.6", true)));
    DeviceInfo other = lavapipe("25.0.7", true);
    other.driverId = vk::DriverId::eNvidiaProprietary;
    other.driver = "NVIDIA: 580.82";
    EXPECT_FALSE(sceneAddressesPay(other));
}

} // namespace
} // namespace vkrt::test
