// glTF alphaMode MASK and BLEND (lib/alpha.glsl), each against a closed form
// worked out here from the glTF 2.0 rules, in both traversal backends (the
// driver's where the device has ray queries). Every test writes its own
// quad glTF (material = "file" in a TOML scene) with a tiny alpha texture:
// - MASK coverage: a quad cut at u = 0.5 fills the view; pixels left of the
//   cut see its emission 1, pixels right of it the black background, and the
//   pixel the cut crosses at a quarter of its width has mean 0.25;
// - MASK shadows: a delta sun shines through a horizontal cut-out onto a
//   Lambert floor: the floor is dark exactly under the kept half and lit
//   (rho E cos / pi) under the cut half;
// - BLEND coverage: alpha = baseColorFactor.a x texture A over an emitter of
//   radiance 1 gives alpha E + (1 - alpha) 1 in expectation (a z-test with
//   the Bernoulli variance);
// - BLEND shadows: the same sun through a uniform BLEND quad leaves the floor
//   (1 - alpha) of its lit radiance in expectation;
// - an emitting MASK cut-out lights a floor as an uncut emitter of its kept
//   half alone (Welch's z of the two images): light sampling does not emit
//   from the holes;
// - the variant: alpha-free scenes get no VKRT_HAS_ALPHA (their kernel is
//   unchanged), alpha-tested ones get it with its binding.
#include "render/KernelVariant.h"
#include "render/Renderer.h"
#include "scene/FeatureSet.h"
#include "scene/SceneParser.h"
#include "shared/Bindings.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

class AlphaRender : public GpuTest {};

/// The backends to test: the own BVH, and the driver's where it has ray queries.
std::vector<bool> backends()
{
    std::vector<bool> list{false};
    if (gpu().deviceInfo().rayQuery()) list.push_back(true);
    else std::printf("[   NOTE   ] %s lacks ray queries: own backend only\n", gpu().deviceInfo().name.c_str());
    return list;
}

std::string backendName(bool driver) { return driver ? "driver" : "own"; }

/// A quad glTF (corners c[0..3] counter-clockwise seen from its front, uv
/// (0, 0), (1, 0), (1, 1), (0, 1) in vkrt's convention, v up) with one
/// material and the textures of `rest`.
std::string quadGltf(const std::array<glm::vec3, 4>& c, const std::string& material, const std::string& rest)
{
    std::string bytes;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& p : c) {
        for (int k = 0; k < 3; ++k) put(bytes, p[k]);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    // glTF's v runs down the image: vkrt's (u, v) is glTF's (u, 1 - v).
    for (float v : {0.f, 1.f, 1.f, 1.f, 1.f, 0.f, 0.f, 0.f}) put(bytes, v);
    for (uint16_t i : {0, 1, 2, 0, 2, 3}) put(bytes, i);
    auto vec = [](glm::vec3 v) {
        return "[" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + "]";
    };
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"material": 0, "attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", bytes) + R"(", "byteLength": 92}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": )" +
           vec(lo) + R"(, "max": )" + vec(hi) + R"(},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
  "materials": [)" +
           material + "]" + rest + "}";
}

/// An RGBA texture `alpha.png` of one row, black, with these alphas left to right.
std::string alphaTexture(const fs::path& dir, const std::vector<uint8_t>& alphas)
{
    std::vector<uint8_t> samples;
    for (uint8_t a : alphas) samples.insert(samples.end(), {0, 0, 0, a});
    write8BitPng(dir / "alpha.png", uint32_t(alphas.size()), 1, 4, samples);
    return R"(, "textures": [{"source": 0, "sampler": 0}], "images": [{"uri": "alpha.png"}],
  "samplers": [{"wrapS": 33071, "wrapT": 33071}])";
}

/// A black glTF material (alphaMode, alphaCutoff, baseColorFactor.a, the
/// alpha texture or none) emitting `emission`.
std::string material(const std::string& mode, double alpha, bool textured, double emission, double cutoff = 0.5)
{
    const std::string e = std::to_string(emission);
    return R"({"alphaMode": ")" + mode + R"(", "alphaCutoff": )" + std::to_string(cutoff) +
           R"(, "emissiveFactor": [)" + e + ", " + e + ", " + e + R"(],
  "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, )" +
           std::to_string(alpha) + R"(], "metallicFactor": 0)" +
           (textured ? R"(, "baseColorTexture": {"index": 0})" : "") + "}}";
}

Scene writeScene(const fs::path& dir, const std::string& gltf, const std::string& toml)
{
    std::ofstream(dir / "quad.gltf") << gltf;
    return parseSceneString(toml + "[[objects]]\nshape = \"mesh\"\nfile = \"quad.gltf\"\nmaterial = \"file\"\n",
                            (dir / "scene.toml").string());
}

/// A 9 x 9 camera on z = 3 looking down -z whose view at z = 0 is the unit
/// square centred on (centreX, 0); a quad at z = 0 spans x, y in [-2, 2].
constexpr uint32_t kSide = 9;
std::string frontView(double centreX)
{
    const double fov = 2.0 * std::atan(0.5 / 3.0) * 180.0 / kPi;
    const std::string x = std::to_string(centreX);
    return "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [" + x + ", 0, 3]\ntarget = [" + x +
           ", 0, 0]\nfov = " + std::to_string(fov) + "\nwidth = " + std::to_string(kSide) +
           "\nheight = " + std::to_string(kSide) + "\n[background]\ncolor = [0, 0, 0]\n";
}
const std::array<glm::vec3, 4> kFrontQuad{glm::vec3(-2, -2, 0), glm::vec3(2, -2, 0), glm::vec3(2, 2, 0),
                                          glm::vec3(-2, 2, 0)};

Image render(const Scene& scene, bool driver, uint32_t frames, RenderOptions options)
{
    options.driverAccel = driver;
    Renderer renderer(gpu(), scene, options);
    EXPECT_EQ(renderer.variant().features.alpha, true);
    renderer.renderFrames(frames);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
    return renderer.mean();
}

// ------------------------------------------------------------------- MASK

TEST_F(AlphaRender, MaskCoversExactlyWhereAlphaReachesTheCutoff)
{
    const fs::path dir = freshTempDir("alpha-mask-coverage");
    // Alpha 1 on the left texel, 0 on the right: bilinear alpha crosses the
    // cutoff 0.5 at u = 0.5, x = 0. The view's left edge is at x = -4.25 / 9,
    // so the cut runs through pixel column 4 a quarter of the way across.
    const std::string gltf = quadGltf(kFrontQuad, material("MASK", 1.0, true, 1.0), alphaTexture(dir, {255, 0}));
    const Scene scene = writeScene(dir, gltf, frontView(0.5 - 4.25 / kSide));
    const uint32_t frames = 256;
    for (bool driver : backends()) {
        SCOPED_TRACE(backendName(driver));
        const Image image = render(scene, driver, frames, statisticalOptions(7));
        double straddle = 0.0;
        for (uint32_t y = 0; y < kSide; ++y) {
            for (uint32_t x = 0; x < kSide; ++x) {
                const double v = image.at(x, y)[0];
                if (x < 4) {
                    EXPECT_NEAR(v, 1.0, 1e-5) << "kept: pixel " << x << ", " << y;
                } else if (x > 4) {
                    EXPECT_EQ(v, 0.0) << "cut out: pixel " << x << ", " << y;
                }
            }
            straddle += image.at(4, y)[0] / kSide;
        }
        // Each sample of column 4 sees 1 with probability 0.25.
        const double sigma = std::sqrt(0.25 * 0.75 / (frames * kSide));
        reportStat("mask_straddle_" + backendName(driver), straddle);
        EXPECT_LT(std::abs(straddle - 0.25) / sigma, 4.5) << "straddling column mean " << straddle;
    }
}

/// A 12 x 12 camera looking straight down at the floor y = 0 over x in [1, 4],
/// z in [-1.5, 1.5] (0.25 a pixel); a delta sun travelling along (2, -1, 0);
/// a horizontal quad at y = 1 over x, z in [-1, 1], facing up, u along x.
/// A floor point (X, 0, Z) sees the sun through the quad's point (X - 2, Z).
constexpr uint32_t kFloorSide = 12;
constexpr double kIrradiance = 2.0, kAlbedo = 0.5;
std::string shadowView()
{
    const double fov = 2.0 * std::atan(1.5 / 5.0) * 180.0 / kPi;
    return "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [2.5, 5, 0]\ntarget = [2.5, 0, 0]\n"
           "up = [0, 0, -1]\nfov = " +
           std::to_string(fov) + "\nwidth = " + std::to_string(kFloorSide) +
           "\nheight = " + std::to_string(kFloorSide) +
           "\n[background]\ncolor = [0, 0, 0]\n[materials.floor]\ntype = \"lambert\"\nalbedo = " +
           std::to_string(kAlbedo) +
           "\n[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nmaterial = \"floor\"\n"
           "[[lights]]\ntype = \"directional\"\ndirection = [2, -1, 0]\nirradiance = " +
           std::to_string(kIrradiance) + "\n";
}
const std::array<glm::vec3, 4> kRoofQuad{glm::vec3(-1, 1, 1), glm::vec3(1, 1, 1), glm::vec3(1, 1, -1),
                                         glm::vec3(-1, 1, -1)};
/// The lit floor's radiance: rho / pi E cos(theta), cos = 1 / sqrt(5).
const double kLit = kAlbedo / kPi * kIrradiance / std::sqrt(5.0);

/// Pixel (x, y)'s floor point: x = 1 + 0.25 (x + 0.5), z = -1.5 + 0.25 (y + 0.5).
bool underQuad(uint32_t y) { return y >= 2 && y <= 9; } // |z| < 1

TEST_F(AlphaRender, MaskCastsTheCutOutsShadow)
{
    const fs::path dir = freshTempDir("alpha-mask-shadow");
    // Kept for u < 0.5 (quad x < 0: floor x in [1, 2], columns 0-3), cut for
    // u > 0.5 (floor x in [2, 3], columns 4-7); beyond x = 3 no quad at all.
    const std::string gltf = quadGltf(kRoofQuad, material("MASK", 1.0, true, 0.0), alphaTexture(dir, {255, 0}));
    const Scene scene = writeScene(dir, gltf, shadowView());
    for (bool driver : backends()) {
        SCOPED_TRACE(backendName(driver));
        const Image image = render(scene, driver, 4, pixelCentreOptions());
        for (uint32_t y = 0; y < kFloorSide; ++y)
            for (uint32_t x = 0; x < kFloorSide; ++x) {
                const bool shadowed = underQuad(y) && x < 4;
                EXPECT_NEAR(image.at(x, y)[0], shadowed ? 0.0 : kLit, 1e-4 * kLit)
                    << (shadowed ? "shadow of the kept half" : "lit") << ": pixel " << x << ", " << y;
            }
    }
}

// ------------------------------------------------------------------ BLEND

TEST_F(AlphaRender, BlendTransmitsOneMinusAlphaInExpectation)
{
    const fs::path dir = freshTempDir("alpha-blend-coverage");
    // alpha = 0.6 x 128/255; the quad emits 0.25 in front of an emitter of
    // radiance 1 at z = -1 (facing +z) that fills the view.
    const double alpha = 0.6 * 128.0 / 255.0, emission = 0.25;
    const std::string gltf =
        quadGltf(kFrontQuad, material("BLEND", 0.6, true, emission), alphaTexture(dir, {128, 128}));
    const std::string back = "[[lights]]\ntype = \"triangle\"\nvertices = [[-3, -3, -1], [3, -3, -1], [3, 3, -1]]\n"
                             "radiance = 1\n[[lights]]\ntype = \"triangle\"\n"
                             "vertices = [[-3, -3, -1], [3, 3, -1], [-3, 3, -1]]\nradiance = 1\n";
    const Scene scene = writeScene(dir, gltf, frontView(0.0) + back);
    const uint32_t frames = 64;
    const double expected = alpha * emission + (1.0 - alpha);
    // One sample is 0.25 with probability alpha, else 1.
    const double sigma = (1.0 - emission) * std::sqrt(alpha * (1.0 - alpha) / (frames * kSide * kSide));
    for (bool driver : backends()) {
        SCOPED_TRACE(backendName(driver));
        const Image image = render(scene, driver, frames, statisticalOptions(driver ? 12 : 11));
        double mean = 0.0, lowest = 1e9, highest = -1e9;
        for (uint32_t y = 0; y < kSide; ++y)
            for (uint32_t x = 0; x < kSide; ++x) {
                const double v = image.at(x, y)[0];
                mean += v / (kSide * kSide);
                lowest = std::min(lowest, v);
                highest = std::max(highest, v);
            }
        reportStat("blend_mean_" + backendName(driver), mean);
        EXPECT_LT(std::abs(mean - expected) / sigma, 4.5) << "mean " << mean << ", expected " << expected;
        // Every pixel mixes the two (not a fixed pattern of kept and passed pixels).
        EXPECT_GT(lowest, emission);
        EXPECT_LT(highest, 1.0);
    }
}

TEST_F(AlphaRender, BlendShadowTransmitsOneMinusAlpha)
{
    const fs::path dir = freshTempDir("alpha-blend-shadow");
    const double alpha = 0.3;
    const std::string gltf = quadGltf(kRoofQuad, material("BLEND", alpha, false, 0.0), "");
    const Scene scene = writeScene(dir, gltf, shadowView());
    const uint32_t frames = 64;
    // Columns 0-7 (floor x in [1, 3]) under rows 2-9 see the sun through the
    // quad: kLit with probability 1 - alpha, else 0; columns 8-11 are lit.
    const double sigma = kLit * std::sqrt(alpha * (1.0 - alpha) / (frames * 8.0 * 8.0));
    for (bool driver : backends()) {
        SCOPED_TRACE(backendName(driver));
        const Image image = render(scene, driver, frames, statisticalOptions(driver ? 22 : 21));
        double mean = 0.0;
        for (uint32_t y = 0; y < kFloorSide; ++y)
            for (uint32_t x = 0; x < kFloorSide; ++x) {
                if (underQuad(y) && x < 8) {
                    mean += image.at(x, y)[0] / 64.0;
                } else {
                    EXPECT_NEAR(image.at(x, y)[0], kLit, 1e-4 * kLit) << "lit: pixel " << x << ", " << y;
                }
            }
        reportStat("blend_shadow_" + backendName(driver), mean / kLit);
        EXPECT_LT(std::abs(mean - (1.0 - alpha) * kLit) / sigma, 4.5)
            << "shadow mean " << mean / kLit << " of lit, expected " << 1.0 - alpha;
    }
}

// ------------------------------------------------------ emitting cut-outs

/// Welch's z of two images' region means (sum of differences over the root
/// of the summed variances of the means).
double welchZ(const Renderer& a, const Renderer& b)
{
    const Image ma = a.mean(), mb = b.mean(), va = a.varianceOfMean(), vb = b.varianceOfMean();
    double d = 0.0, v = 0.0;
    for (size_t i = 0; i < ma.rgb.size(); i += 3) {
        d += double(ma.rgb[i]) - mb.rgb[i];
        v += double(va.rgb[i]) + vb.rgb[i];
    }
    return d / std::sqrt(v);
}

TEST_F(AlphaRender, AnEmittingCutOutLightsLikeItsKeptPartAlone)
{
    // An emitting quad at y = 1 facing a Lambert floor, MASK-cut to
    // its half x < 0, against a quad of that half alone: light
    // sampling must not emit from the holes (lib/alpha.glsl: emitterCoverage).
    const fs::path dir = freshTempDir("alpha-emitter");
    const std::string view =
        "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [0, 3, 4]\ntarget = [0, 0, 0]\n"
        "fov = 50\nwidth = 24\nheight = 24\n[background]\ncolor = [0, 0, 0]\n[materials.floor]\n"
        "type = \"lambert\"\nalbedo = 0.5\n[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\n"
        "normal = [0, 1, 0]\nmaterial = \"floor\"\n";
    // Corners ordered so that the quad faces (and emits) down, u along +x.
    const std::array<glm::vec3, 4> full{glm::vec3(-1, 1, -1), glm::vec3(1, 1, -1), glm::vec3(1, 1, 1),
                                        glm::vec3(-1, 1, 1)};
    const std::array<glm::vec3, 4> half{glm::vec3(-1, 1, -1), glm::vec3(0, 1, -1), glm::vec3(0, 1, 1),
                                        glm::vec3(-1, 1, 1)};
    const Scene cut =
        writeScene(dir, quadGltf(full, material("MASK", 1.0, true, 1.0), alphaTexture(dir, {255, 0})), view);
    const fs::path halfDir = freshTempDir("alpha-emitter-half");
    // Kept everywhere (alpha 1), so that both scenes share one kernel variant.
    const Scene whole =
        writeScene(halfDir, quadGltf(half, material("MASK", 1.0, true, 1.0), alphaTexture(halfDir, {255, 255})), view);
    for (bool driver : backends()) {
        SCOPED_TRACE(backendName(driver));
        RenderOptions a = statisticalOptions(driver ? 32 : 31), b = statisticalOptions(driver ? 34 : 33);
        a.driverAccel = b.driverAccel = driver;
        Renderer cutRenderer(gpu(), cut, a), halfRenderer(gpu(), whole, b);
        cutRenderer.renderFrames(64);
        halfRenderer.renderFrames(64);
        const double z = welchZ(cutRenderer, halfRenderer);
        reportStat("emitter_cut_z_" + backendName(driver), z);
        reportStat("emitter_cut_mean_" + backendName(driver), channelMean(cutRenderer.mean(), 0));
        reportStat("emitter_half_mean_" + backendName(driver), channelMean(halfRenderer.mean(), 0));
        EXPECT_LT(std::abs(z), 4.5) << "cut-out " << channelMean(cutRenderer.mean(), 0) << ", half quad "
                                    << channelMean(halfRenderer.mean(), 0);
    }
}

// ---------------------------------------------------------------- variant

TEST(AlphaVariant, OnlyAlphaTestedMaterialsBringTheAlphaKernel)
{
    const fs::path dir = freshTempDir("alpha-variant");
    for (const std::string mode : {"OPAQUE", "MASK", "BLEND"}) {
        const Scene scene = writeScene(dir, quadGltf(kFrontQuad, material(mode, 0.5, false, 1.0), ""), frontView(0));
        KernelVariant variant;
        variant.features = featuresOf(scene);
        const auto defines = variant.defines();
        const bool hasDefine = std::any_of(defines.begin(), defines.end(),
                                           [](const auto& d) { return d.first == "VKRT_HAS_ALPHA"; });
        const auto bindings = variant.bindings();
        const bool hasBinding = std::find(bindings.begin(), bindings.end(), gpu::BINDING_MATERIAL_ALPHA) !=
                                bindings.end();
        EXPECT_EQ(hasDefine, mode != "OPAQUE") << mode;
        EXPECT_EQ(hasBinding, mode != "OPAQUE") << mode;
        EXPECT_EQ(scene.materials.back().alphaMode,
                  mode == "MASK" ? AlphaMode::Mask : mode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque);
    }
}

} // namespace
} // namespace vkrt::test
