// A glTF file rendered as a scene against the same scene written by hand in
// vkrt's TOML (scenes/gltf/lights-camera.*, both made by tools/gltf_writer.py,
// which computes every world-space number of the TOML in double precision):
// statistically equal images check the node transforms, the camera and light
// conventions and the file materials together. Likewise a texture under
// KHR_texture_transform against the same quad with the transform baked into
// its uvs (scenes/gltf/texture-transform*.gltf).
#include "render/Renderer.h"
#include "render/RenderSession.h"
#include "scene/GltfScene.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = VKRT_TEST_SOURCE_DIR;

class GltfRender : public GpuTest {};

struct Rendered {
    Image mean, variance;
};

Rendered render(const Scene& scene, uint32_t seed, uint32_t spp)
{
    RenderOptions options = statisticalOptions(seed);
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(spp);
    return {renderer.mean(), renderer.varianceOfMean()};
}

/// Welch's z per value against a Sidak-corrected alpha of 0.01, and the pooled
/// z per channel within 4.
void expectStatisticallyEqual(const Rendered& a, const Rendered& b, const std::string& what)
{
    ASSERT_EQ(a.mean.rgb.size(), b.mean.rgb.size());
    const size_t n = a.mean.rgb.size();
    const double limit = 4.9; // two-sided alpha 0.01 Sidak-corrected over ~60,000 values
    size_t failed = 0;
    double difference[3] = {}, variance[3] = {};
    for (size_t i = 0; i < n; ++i) {
        const double d = double(a.mean.rgb[i]) - b.mean.rgb[i];
        const double v = double(a.variance.rgb[i]) + b.variance.rgb[i];
        difference[i % 3] += d;
        variance[i % 3] += v;
        if (v > 0 ? std::abs(d) / std::sqrt(v) > limit : d != 0.0) ++failed;
    }
    EXPECT_LE(double(failed) / double(n), 0.0025) << what << ": " << failed << " of " << n << " values differ";
    for (int c = 0; c < 3; ++c) {
        const double z = difference[c] / std::sqrt(variance[c]);
        reportStat(what + "_pooled_z_" + std::to_string(c), z);
        EXPECT_LT(std::abs(z), 4.0) << what << " channel " << c;
    }
}

TEST_F(GltfRender, AGltfSceneRendersAsItsHandWrittenToml)
{
    const Scene toml = parseSceneFile((kSource / "scenes/gltf/lights-camera.toml").string());
    Scene gltf = parseGltfScene((kSource / "scenes/gltf/lights-camera.gltf").string());
    gltf.render = toml.render;         // the TOML states no [render]: vkrt's defaults
    gltf.background = toml.background; // and no background: black, as the glTF (which has lights)
    applyResolution(gltf.camera, {toml.camera.width, toml.camera.height});
    expectStatisticallyEqual(render(toml, 1, 256), render(gltf, 2, 256), "lights_camera");
}

TEST_F(GltfRender, TextureTransformEqualsTheTransformBakedIntoTheUvs)
{
    const fs::path dir = kSource / "scenes/gltf";
    Scene a = parseGltfScene((dir / "texture-transform.gltf").string());
    Scene b = parseGltfScene((dir / "texture-transform-baked.gltf").string());
    for (Scene* s : {&a, &b}) applyResolution(s->camera, {160, 120});
    expectStatisticallyEqual(render(a, 1, 128), render(b, 2, 128), "texture_transform");
}

} // namespace
} // namespace vkrt::test
