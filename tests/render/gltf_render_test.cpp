// A glTF file rendered as a scene against the same scene written by hand in
// vkrt's TOML (scenes/gltf/lights-camera.*, both made by tools/gltf_writer.py,
// which computes every world-space number of the TOML in double precision):
// statistically equal images check the node transforms, the camera and light
// conventions and the file materials together. Likewise a texture under
// KHR_texture_transform against the same quad with the transform baked into
// its uvs (scenes/gltf/texture-transform*.gltf).
#include "mesh/MeshGeometry.h"
#include "render/RenderSession.h"
#include "render/Renderer.h"
#include "scene/FeatureSet.h"
#include "scene/GltfScene.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>

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

/// The white sky these closed forms were written for, in place of a glTF
/// file's studio default (render/Environment.h: studioEnvironment).
void useWhiteSky(Scene& scene)
{
    scene.background.environment.reset();
    scene.background.color = Color(1.0);
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

/// triangleBuffer's 92 bytes, then two instance translations and two scales (48 bytes).
std::string instanceBuffer()
{
    std::string bytes = triangleBuffer();
    for (float v : {0.f, 1.f, -1.f, 0.5f, 0.4f, 0.3f}) put(bytes, v);
    for (float v : {1.f, 1.f, 1.f, 0.5f, 0.5f, 0.5f}) put(bytes, v);
    return bytes;
}

/// Instances of one triangle: nodes placing it (one mirrored, one moved by
/// 0.004, one turned), EXT_mesh_gpu_instancing copies, and a camera.
std::string instancedGltf()
{
    return R"({"asset": {"version": "2.0"}, "scene": 0,
  "extensionsUsed": ["EXT_mesh_gpu_instancing"],
  "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
  "nodes": [{"mesh": 0, "translation": [-1.5, -1, 0]},
            {"mesh": 0, "translation": [1.5, -1, 0], "scale": [-1, 1, 1]},
            {"mesh": 0, "translation": [-1.496, 0.2, -0.5], "rotation": [0, 0.3826834, 0, 0.9238795]},
            {"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 4, "SCALE": 5}}}},
            {"camera": 0, "translation": [0, 0, 5]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.3333333, "znear": 0.1}}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0,
                                          "roughnessFactor": 0.5}, "doubleSided": true}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 3, "material": 0}]}],
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", instanceBuffer()) + R"(", "byteLength": 140}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 24}, {"buffer": 0, "byteOffset": 84, "byteLength": 6},
                  {"buffer": 0, "byteOffset": 92, "byteLength": 24}, {"buffer": 0, "byteOffset": 116, "byteLength": 24}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"},
    {"bufferView": 4, "componentType": 5126, "count": 2, "type": "VEC3"},
    {"bufferView": 5, "componentType": 5126, "count": 2, "type": "VEC3"}]})";
}

TEST_F(GltfRender, InstancesRenderAsTheFlattenedMesh)
{
    // The same file as a glTF scene (one geometry, five instances) and as one
    // mesh object of a TOML scene (loadMeshFile flattens the instances into
    // world-space triangles): the same camera, sky and material, so the same image.
    const fs::path dir = freshTempDir("gltf-instances");
    std::ofstream(dir / "instances.gltf") << instancedGltf();
    Scene instanced = parseGltfScene((dir / "instances.gltf").string());
    useWhiteSky(instanced);
    ASSERT_EQ(instanced.meshes.size(), 5u);
    applyResolution(instanced.camera, {160, 120});
    const Scene flat = parseSceneString(R"(
[render]
integrator = "path"
max_depth = 8
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov = 45.836623610465857
width = 160
height = 120
[background]
color = [1, 1, 1]
[[objects]]
shape = "mesh"
file = ")" + (dir / "instances.gltf").string() +
                                        R"("
material = "file"
)");
    ASSERT_EQ(flat.meshes.size(), 1u);
    EXPECT_EQ(flat.meshes[0].geometry->data.triangles.size(), 5u);
    expectStatisticallyEqual(render(instanced, 1, 128), render(flat, 2, 128), "instances");
}

/// A 2 x 2 quad in the z = 0 plane (a black dielectric) seen by an
/// orthographic camera `distance` ahead of it on +z, its view 4 wide and 3 tall.
/// With `colorAlpha`, the quad's vertices get COLOR_0 = (1, 1, 1, colorAlpha).
std::string
orthographicQuadGltf(double distance,
                     const std::string& material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                                                   "metallicFactor": 0}})",
                     const std::string& extensionsUsed = "[]", std::optional<float> colorAlpha = {})
{
    std::string bytes;
    for (float v : {-1.f, -1.f, 0.f, 1.f, -1.f, 0.f, 1.f, 1.f, 0.f, -1.f, 1.f, 0.f}) put(bytes, v);
    for (uint16_t i : {0, 1, 2, 0, 2, 3}) put(bytes, i);
    for (int k = 0; k < 4 && colorAlpha; ++k)
        for (float v : {1.f, 1.f, 1.f, *colorAlpha}) put(bytes, v); // at 60: 64 bytes
    const std::string colors = colorAlpha ? R"(, "COLOR_0": 2)" : "";
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}], "extensionsUsed": )" +
           extensionsUsed + R"(,
  "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, )" +
           std::to_string(distance) + R"(]}],
  "cameras": [{"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 1.5, "znear": 0.01, "zfar": 100}}],
  "materials": [)" +
           material + R"(],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0)" +
           colors + R"(}, "indices": 1, "material": 0}]}],
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", bytes) + R"(", "byteLength": )" + std::to_string(bytes.size()) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12})" +
           (colorAlpha ? R"(, {"buffer": 0, "byteOffset": 60, "byteLength": 64})" : "") + R"(],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"})" +
           (colorAlpha ? R"(, {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC4"})" : "") + R"(]})";
}

TEST_F(GltfRender, AnOrthographicCameraSeesTheSameAtEveryDistance)
{
    // Parallel rays: the quad covers the same pixels 2 or 20 units away (a
    // perspective camera would see it ten times smaller), and exactly its
    // share of the view: 2 x 2 of 4 x 3 (columns 40-119, rows 20-99 of 160 x 120).
    const fs::path dir = freshTempDir("gltf-orthographic");
    std::ofstream(dir / "near.gltf") << orthographicQuadGltf(2.0);
    std::ofstream(dir / "far.gltf") << orthographicQuadGltf(20.0);
    Scene near = parseGltfScene((dir / "near.gltf").string());
    Scene far = parseGltfScene((dir / "far.gltf").string());
    useWhiteSky(near);
    useWhiteSky(far);
    EXPECT_EQ(near.camera.orthographicHeight, 3.0);
    EXPECT_EQ(double(near.camera.width) / near.camera.height, 640.0 / 480.0);
    for (Scene* s : {&near, &far}) applyResolution(s->camera, {160, 120});
    const Rendered a = render(near, 1, 64), b = render(far, 2, 64);
    expectStatisticallyEqual(a, b, "orthographic");
    // Inside the quad only its dim reflection of the white sky; outside, the sky (1).
    auto luminance = [&](uint32_t x, uint32_t y) { return a.mean.rgb[3 * (y * 160 + x) + 1]; };
    EXPECT_LT(luminance(80, 60), 0.2f);
    EXPECT_LT(luminance(41, 21), 0.2f);
    EXPECT_LT(luminance(118, 98), 0.2f);
    EXPECT_EQ(luminance(38, 60), 1.0f);
    EXPECT_EQ(luminance(121, 60), 1.0f);
    EXPECT_EQ(luminance(80, 18), 1.0f);
}

TEST_F(GltfRender, AnUnlitSurfaceIsItsBaseColourWhateverLightsIt)
{
    // KHR_materials_unlit: the camera sees baseColorFactor exactly, under the
    // white sky and with a sun on it alike (a lit surface would differ).
    const std::string unlit = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.5, 0.75, 1]},
                                  "extensions": {"KHR_materials_unlit": {}}})";
    const fs::path dir = freshTempDir("gltf-unlit");
    std::ofstream(dir / "unlit.gltf") << orthographicQuadGltf(2.0, unlit, R"(["KHR_materials_unlit"])");
    Scene scene = parseGltfScene((dir / "unlit.gltf").string());
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_EQ(scene.materials[0].emission, Color(0.25, 0.5, 0.75));
    applyResolution(scene.camera, {160, 120});
    for (bool sun : {false, true}) {
        if (sun) scene.directionalLights.push_back({glm::normalize(glm::dvec3(-1, -1, -1)), Color(3.0), 0.0});
        const Rendered r = render(scene, 3, 16);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(r.mean.rgb[3 * (60 * 160 + 80) + size_t(c)], 0.25 * (c + 1), 1e-5) << "sun " << sun;
    }
}

TEST_F(GltfRender, VertexColoursTintTheBaseColourAndTheirAlphaCutsOut)
{
    // COLOR_0 multiplies the base colour, and its alpha the coverage: a white
    // lambertian-like quad tinted by (1, 1, 1, a) is there for a >= the MASK
    // cutoff and gone (the white sky, exactly 1) below it.
    const std::string mask = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
                                 "alphaMode": "MASK", "alphaCutoff": 0.5})";
    const fs::path dir = freshTempDir("gltf-vertex-alpha");
    std::ofstream(dir / "kept.gltf") << orthographicQuadGltf(2.0, mask, "[]", 0.75f);
    std::ofstream(dir / "cut.gltf") << orthographicQuadGltf(2.0, mask, "[]", 0.25f);
    for (const char* name : {"kept.gltf", "cut.gltf"}) {
        Scene scene = parseGltfScene((dir / name).string());
        useWhiteSky(scene);
        applyResolution(scene.camera, {160, 120});
        EXPECT_TRUE(featuresOf(scene).vertexColors && featuresOf(scene).alpha) << name;
        const Rendered r = render(scene, 5, 8);
        const float centre = r.mean.rgb[3 * (60 * 160 + 80) + 1];
        if (std::string(name) == "cut.gltf") EXPECT_EQ(centre, 1.0f) << "a vertex alpha of 0.25 under the cutoff";
        else EXPECT_LT(centre, 0.9f) << "a vertex alpha of 0.75 keeps the (grey) quad";
    }
}

} // namespace
} // namespace vkrt::test
