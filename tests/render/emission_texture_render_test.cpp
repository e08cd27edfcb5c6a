// glTF emissive textures on the GPU (emissiveTexture x emissiveFactor x
// KHR_materials_emissive_strength), each checked against an answer worked out
// here from the texels and the documented conventions, not from the texture code:
// - an emissive quad seen head-on shows texel x factor x strength at every
//   pixel centre, with either integrator and either traversal backend;
// - a Lambert floor under a textured emissive quad (light sampling with the
//   texture at the sampled point, MIS against BSDF-sampled hits that read the
//   texture at the hit) converges to (albedo / pi) x the irradiance integral
//   over the texture, computed here by a midpoint rule over bilinear texels;
// both with the texture read through TEXCOORD_0 and through TEXCOORD_1.
#include "mesh/MeshGeometry.h"
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureImage.h"
#include "texture/TextureTestFiles.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

class EmissionTextureRender : public GpuTest {};

/// A 16 x 16 sRGB texture of 4 x 4 blocks of 4 x 4 texels, each block its own
/// colour (rows top to bottom as in the file); some blocks black in a channel.
struct BlockTexture {
    static constexpr uint32_t kSide = 16;
    static std::array<uint8_t, 3> block(uint32_t bx, uint32_t by)
    {
        return {uint8_t((bx + by) % 2 ? 0 : 255), uint8_t(64 * bx + 32), uint8_t(by < 2 ? 200 : 0)};
    }
    static std::array<uint8_t, 3> texel(uint32_t x, uint32_t y) { return block(x / 4, y / 4); }
    static void write(const fs::path& file)
    {
        std::vector<uint8_t> samples;
        for (uint32_t y = 0; y < kSide; ++y)
            for (uint32_t x = 0; x < kSide; ++x) {
                const auto c = texel(x, y);
                samples.insert(samples.end(), c.begin(), c.end());
            }
        write8BitPng(file, kSide, kSide, 3, samples);
    }
    /// The bilinear lookup (repeat wrap, glTF's default sampler) at glTF uv
    /// (u, v), v down from the top row: texel (x, y)'s centre is ((x + 0.5) / 16, (y + 0.5) / 16).
    static glm::dvec3 bilinear(double u, double v)
    {
        const double s = u * kSide - 0.5, t = v * kSide - 0.5;
        const double fs = std::floor(s), ft = std::floor(t);
        auto at = [](int x, int y) {
            const auto c = texel(uint32_t((x + 16) % 16), uint32_t((y + 16) % 16));
            return glm::dvec3(srgbToLinear(c[0] / 255.0), srgbToLinear(c[1] / 255.0), srgbToLinear(c[2] / 255.0));
        };
        const int x = int(fs), y = int(ft);
        const double a = s - fs, b = t - ft;
        return (1 - b) * ((1 - a) * at(x, y) + a * at(x + 1, y)) + b * ((1 - a) * at(x, y + 1) + a * at(x + 1, y + 1));
    }
};

/// emissiveFactor (1, 0.5, 0.25) x emissiveStrength 4, black base colour.
const glm::dvec3 kFactor(4.0, 2.0, 1.0);

/// The emissive material, its texture read through TEXCOORD_`uvSet`.
std::string emissiveMaterial(int uvSet)
{
    return R"("extensionsUsed": ["KHR_materials_emissive_strength"],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 0.5, 0.25],
    "emissiveTexture": {"index": 0, "texCoord": )" +
           std::to_string(uvSet) + R"(},
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}],
  "textures": [{"source": 0}], "images": [{"uri": "blocks.png"}])";
}

/// `quad` with its uvs moved to TEXCOORD_1 for uvSet 1, TEXCOORD_0 then one
/// constant point of another block (a lookup through the wrong set would show it).
GltfQuad withUvSet(GltfQuad quad, int uvSet)
{
    if (uvSet == 1) {
        quad.uv1 = quad.uv;
        quad.uv.fill({0.9f, 0.1f});
    }
    return quad;
}

// ------------------------------------------------------------- seen directly

constexpr uint32_t kSide = 33; // the view at z = 0 is exactly [-0.5, 0.5]^2

/// The quad [-0.5, 0.5]^2 at z = 0 facing +z, the image upright on it, seen
/// head-on from +z.
Scene headOnScene(const fs::path& dir, const std::string& integrator, int uvSet = 0)
{
    BlockTexture::write(dir / "blocks.png");
    const GltfQuad quad{{{{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}}},
                        {{{0, 1}, {1, 1}, {1, 0}, {0, 0}}}};
    writeText(dir / "quad.gltf", quadsGltf({withUvSet(quad, uvSet)}, emissiveMaterial(uvSet)));
    const double fov = 2.0 * std::atan(0.5 / 3.0) * 180.0 / kPi;
    return parseSceneString("[render]\nintegrator = \"" + integrator +
                                "\"\nmax_depth = 1\n[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = " +
                                std::to_string(fov) + "\nwidth = " + std::to_string(kSide) +
                                "\nheight = " + std::to_string(kSide) +
                                "\n[[objects]]\nshape = \"mesh\"\nfile = \"quad.gltf\"\nmaterial = \"file\"\n",
                            (dir / "scene.toml").string());
}

/// Pixel (x, y)'s centre sees texel (x, y) of the image scaled to the view;
/// every pixel whose centre is at least a texel from a block's edge shows that
/// block's colour x factor exactly (the bilinear weights all fall in it).
void expectTexels(const Image& image, const std::string& what)
{
    uint32_t checked = 0;
    for (uint32_t y = 0; y < kSide; ++y)
        for (uint32_t x = 0; x < kSide; ++x) {
            const double u = (x + 0.5) / kSide, v = (y + 0.5) / kSide; // glTF uv: v down
            const double bu = u * 4.0 - std::floor(u * 4.0), bv = v * 4.0 - std::floor(v * 4.0);
            if (bu < 0.25 || bu > 0.75 || bv < 0.25 || bv > 0.75) continue;
            const auto c = BlockTexture::block(uint32_t(u * 4.0), uint32_t(v * 4.0));
            for (int k = 0; k < 3; ++k) {
                const double expected = srgbToLinear(c[k] / 255.0) * kFactor[k];
                EXPECT_NEAR(image.at(x, y)[k], expected, 2e-4 * std::max(1.0, expected))
                    << what << ": pixel (" << x << ", " << y << ") channel " << k;
            }
            ++checked;
        }
    EXPECT_GE(checked, 100u);
}

Image renderCentres(const Scene& scene, bool driver)
{
    RenderOptions options = pixelCentreOptions();
    options.driverAccel = driver;
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(1);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
    return renderer.mean();
}

TEST_F(EmissionTextureRender, AQuadSeenHeadOnShowsTexelTimesFactorTimesStrength)
{
    const fs::path dir = freshTempDir("emission-head-on");
    expectTexels(renderCentres(headOnScene(dir, "path"), false), "path, own BVH");
    expectTexels(renderCentres(headOnScene(dir, "whitted"), false), "whitted, own BVH");
    if (gpu().deviceInfo().rayQuery())
        expectTexels(renderCentres(headOnScene(dir, "path"), true), "path, driver");
    else
        RecordProperty("driver", "skipped: " + gpu().deviceInfo().rayQueryMissing);
}

TEST_F(EmissionTextureRender, ATextureReadThroughTheSecondUvSetShowsItsTexels)
{
    // texCoord 1: the hit reads TEXCOORD_1 (TEXCOORD_0 points at one other block throughout).
    const fs::path dir = freshTempDir("emission-uv1");
    const Scene scene = headOnScene(dir, "path", 1);
    ASSERT_FALSE(scene.meshes.front().geometry->data.uvs1.empty());
    expectTexels(renderCentres(scene, false), "TEXCOORD_1, path, own BVH");
}

// ---------------------------------------------------- direct light, MIS

constexpr uint32_t kFloorSide = 24;
constexpr double kHalfView = 0.6; // the view at z = 0 is [-0.6, 0.6]^2
constexpr double kEyeHeight = 0.9;
constexpr double kAlbedo = 0.5;

/// A Lambert floor at z = 0 seen straight down from z = 0.9, lit only by the
/// textured quad [-0.5, 0.5]^2 at z = 1 facing down (the image upright seen
/// from above: glTF v down along -y).
Scene floorScene(const fs::path& dir, int uvSet)
{
    BlockTexture::write(dir / "blocks.png");
    const GltfQuad quad{{{{-0.5f, -0.5f, 1}, {-0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}, {0.5f, -0.5f, 1}}},
                        {{{0, 1}, {0, 0}, {1, 0}, {1, 1}}}};
    writeText(dir / "light.gltf", quadsGltf({withUvSet(quad, uvSet)}, emissiveMaterial(uvSet)));
    const double fov = 2.0 * std::atan(kHalfView / kEyeHeight) * 180.0 / kPi;
    return parseSceneString("[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [0, 0, " +
                                std::to_string(kEyeHeight) + "]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\nfov = " +
                                std::to_string(fov) + "\nwidth = " + std::to_string(kFloorSide) +
                                "\nheight = " + std::to_string(kFloorSide) +
                                "\n[materials.floor]\ntype = \"lambert\"\nalbedo = " + std::to_string(kAlbedo) +
                                "\n[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n"
                                "material = \"floor\"\n[[objects]]\nshape = \"mesh\"\nfile = \"light.gltf\"\n"
                                "material = \"file\"\n[background]\ncolor = [0, 0, 0]\n",
                            (dir / "scene.toml").string());
}

/// Radiance of the floor at (px, py): albedo / pi x the integral over the
/// quad of L(y) cos cos / r^2 = L / r^4 (height 1), L = factor x the bilinear
/// texture; midpoint rule on n x n cells of the radiance sampled once.
std::vector<glm::dvec3> floorReference()
{
    constexpr int n = 256;
    std::vector<glm::dvec3> radiance(size_t(n) * n);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double u = (i + 0.5) / n, v = (j + 0.5) / n; // glTF uv; world x = u - 0.5, y = 0.5 - v
            radiance[size_t(j) * n + i] = kFactor * BlockTexture::bilinear(u, v);
        }
    std::vector<glm::dvec3> reference;
    for (uint32_t y = 0; y < kFloorSide; ++y)
        for (uint32_t x = 0; x < kFloorSide; ++x) {
            // Pixel centres: x right along +x, rows top (+y) to bottom.
            const double px = kHalfView * (2.0 * (x + 0.5) / kFloorSide - 1.0);
            const double py = kHalfView * (1.0 - 2.0 * (y + 0.5) / kFloorSide);
            glm::dvec3 sum(0.0);
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const double qx = (i + 0.5) / n - 0.5, qy = 0.5 - (j + 0.5) / n;
                    const double r2 = (qx - px) * (qx - px) + (qy - py) * (qy - py) + 1.0;
                    sum += radiance[size_t(j) * n + i] / (r2 * r2);
                }
            reference.push_back(sum / double(n * n) * kAlbedo / kPi);
        }
    return reference;
}

class EmissionTextureFloor : public GpuTest, public ::testing::WithParamInterface<int> {};

// Parameter: the uv set the emissive texture reads (1: the emitters' sampled
// points and the BSDF-sampled hits both read TEXCOORD_1).
TEST_P(EmissionTextureFloor, AFloorUnderATexturedQuadConvergesToTheTextureIntegral)
{
    const Scene scene = floorScene(freshTempDir("emission-floor"), GetParam());
    RenderOptions options = statisticalOptions(7);
    options.jitter = false; // each pixel estimates the radiance at its centre's point
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(512);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
    const Image mean = renderer.mean(), variance = renderer.varianceOfMean();
    const std::vector<glm::dvec3> reference = floorReference();
    // Per value: |z| within 4.8 (two-sided alpha 0.01, Sidak over 1728 values);
    // pooled per channel within 4.
    size_t failed = 0;
    double difference[3] = {}, pooled[3] = {};
    for (uint32_t y = 0; y < kFloorSide; ++y)
        for (uint32_t x = 0; x < kFloorSide; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = mean.at(x, y)[c] - reference[y * kFloorSide + x][c];
                const double v = variance.at(x, y)[c];
                difference[c] += d;
                pooled[c] += v;
                if (v > 0 ? std::abs(d) / std::sqrt(v) > 4.8 : std::abs(d) > 1e-6) {
                    if (++failed <= 5)
                        ADD_FAILURE() << "pixel (" << x << ", " << y << ") channel " << c << ": " << mean.at(x, y)[c]
                                  << " against " << reference[y * kFloorSide + x][c] << " +- " << std::sqrt(v);
                }
            }
    EXPECT_EQ(failed, 0u);
    for (int c = 0; c < 3; ++c) {
        const double z = difference[c] / std::sqrt(pooled[c]);
        reportStat("emission_floor_uv" + std::to_string(GetParam()) + "_pooled_z_" + std::to_string(c), z);
        EXPECT_LT(std::abs(z), 4.0) << "channel " << c;
    }
}

INSTANTIATE_TEST_SUITE_P(UvSet, EmissionTextureFloor, ::testing::Values(0, 1),
                         [](const ::testing::TestParamInfo<int>& info) {
                             return "TEXCOORD_" + std::to_string(info.param);
                         });

} // namespace
} // namespace vkrt::test
