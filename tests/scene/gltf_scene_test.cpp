// A glTF file as a scene (scene/GltfScene.h): its camera and lights placed by
// their nodes' world transforms, as the hand-written TOML of the same scene
// (scenes/gltf/lights-camera.toml, every number computed independently by
// tools/gltf_writer.py) states them; the defaults for a file without camera
// or lights; `[import] gltf`; and bad input named with the file.
#include "mesh/MeshGeometry.h"
#include "scene/FeatureSet.h"
#include "scene/GltfScene.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = VKRT_TEST_SOURCE_DIR;

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tolerance, const std::string& what)
{
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tolerance) << what << "[" << i << "]";
}

TEST(GltfScene, CameraAndLightsAreThoseTheNodesPlace)
{
    const Scene gltf = parseGltfScene((kSource / "scenes/gltf/lights-camera.gltf").string());
    const Scene toml = parseSceneFile((kSource / "scenes/gltf/lights-camera.toml").string());
    // The camera: same eye, view direction, up and vertical fov (float32 in the file).
    expectNear(gltf.camera.eye, toml.camera.eye, 1e-6, "eye");
    expectNear(glm::normalize(gltf.camera.target - gltf.camera.eye),
               glm::normalize(toml.camera.target - toml.camera.eye), 1e-6, "view direction");
    expectNear(glm::normalize(gltf.camera.up), glm::normalize(toml.camera.up), 1e-6, "up");
    EXPECT_NEAR(gltf.camera.fovY, toml.camera.fovY, 1e-5);
    EXPECT_EQ(double(gltf.camera.width) / gltf.camera.height, double(toml.camera.width) / toml.camera.height);
    // The lights, in the file's node order.
    ASSERT_EQ(gltf.pointLights.size(), toml.pointLights.size());
    ASSERT_EQ(gltf.spotLights.size(), toml.spotLights.size());
    ASSERT_EQ(gltf.directionalLights.size(), toml.directionalLights.size());
    ASSERT_GT(gltf.pointLights.size() + gltf.spotLights.size() + gltf.directionalLights.size(), 2u);
    for (size_t i = 0; i < gltf.pointLights.size(); ++i) {
        expectNear(gltf.pointLights[i].position, toml.pointLights[i].position, 1e-6, "point position");
        expectNear(gltf.pointLights[i].intensity, toml.pointLights[i].intensity, 1e-6, "point intensity");
    }
    for (size_t i = 0; i < gltf.spotLights.size(); ++i) {
        const SpotLight &a = gltf.spotLights[i], &b = toml.spotLights[i];
        expectNear(a.position, b.position, 1e-6, "spot position");
        expectNear(a.direction, b.direction, 1e-6, "spot direction");
        expectNear(a.intensity, b.intensity, 1e-6, "spot intensity");
        EXPECT_NEAR(a.innerConeAngle, b.innerConeAngle, 1e-5);
        EXPECT_NEAR(a.outerConeAngle, b.outerConeAngle, 1e-5);
    }
    for (size_t i = 0; i < gltf.directionalLights.size(); ++i) {
        expectNear(gltf.directionalLights[i].direction, toml.directionalLights[i].direction, 1e-6, "sun direction");
        expectNear(gltf.directionalLights[i].irradiance, toml.directionalLights[i].irradiance, 1e-6, "irradiance");
    }
    // Lit by its own lights: no sky; the path integrator.
    EXPECT_EQ(gltf.background.color, Color(0.0));
    EXPECT_EQ(gltf.render.integrator, Integrator::Path);
    // Four nodes place three meshes (mesh 1 twice): four instances, mesh 1's two sharing one geometry.
    ASSERT_EQ(gltf.meshes.size(), 4u);
    EXPECT_FALSE(gltf.meshes[0].fileMaterials.empty());
    EXPECT_EQ(gltf.meshes[1].geometry, gltf.meshes[2].geometry);
    EXPECT_NE(gltf.meshes[0].geometry, gltf.meshes[1].geometry);
}

TEST(GltfScene, AnotherCameraByIndexOrNameAndAClearErrorForNone)
{
    const std::string file = (kSource / "scenes/gltf/lights-camera.gltf").string();
    const Scene byIndex = parseGltfScene(file, {std::string("0"), std::nullopt});
    EXPECT_GT(byIndex.camera.fovY, 0.0);
    const std::string error = inputErrorOf([&] { parseGltfScene(file, {std::string("7"), std::nullopt}); });
    EXPECT_NE(error.find("--camera 7: "), std::string::npos) << error;
    EXPECT_NE(error.find("has no such camera"), std::string::npos) << error;
}

/// The one-triangle glTF of the test support in a fresh folder, with `rest`
/// added to its top-level object and `nodes` (JSON of the scene's roots and
/// its nodes array; node 0 must be the triangle's) in place of its own.
fs::path writeTriangle(const std::string& name, const std::string& rest,
                       const std::string& nodes = R"("scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}])")
{
    const fs::path dir = freshTempDir(name);
    std::string text = triangleGltf(rest.empty() ? R"("extras": {})" : rest, "");
    const std::string own = R"("scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}])";
    text.replace(text.find(own), own.size(), nodes);
    writeText(dir / "scene.gltf", text);
    return dir / "scene.gltf";
}

TEST(GltfScene, WithoutCameraOrLightsItFramesTheBoxInTheStudio)
{
    const Scene scene = parseGltfScene(writeTriangle("gltf-bare", "").string());
    ASSERT_TRUE(scene.background.environment.has_value());
    EXPECT_TRUE(scene.background.environment->studio);
    EXPECT_TRUE(scene.background.environment->path.empty());
    EXPECT_EQ(scene.background.color, Color(0.0));
    // The triangle (0,0,0) (1,0,0) (0,1,0) is in front of the camera.
    const glm::dvec3 view = glm::normalize(scene.camera.target - scene.camera.eye);
    EXPECT_GT(glm::dot(glm::dvec3(1.0 / 3, 1.0 / 3, 0) - scene.camera.eye, view), 0.0);
    EXPECT_LT(glm::length(scene.camera.target - glm::dvec3(0.5, 0.5, 0.0)), 1e-9);
}

TEST(GltfScene, BadCamerasAndLightsNameTheFile)
{
    const fs::path a =
        writeTriangle("gltf-zero-fov",
                      R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0, "znear": 0.1}}])",
                      R"("scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}])");
    std::string error = inputErrorOf([&] { parseGltfScene(a.string()); });
    EXPECT_NE(error.find(a.string() + ": cameras[0].perspective.yfov: must be strictly between 0 and pi"),
              std::string::npos)
        << error;

    const fs::path b = writeTriangle("gltf-bad-light", R"("extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": -1}]}})",
                                     R"("scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"extensions": {"KHR_lights_punctual": {"light": 0}}}])");
    error = inputErrorOf([&] { parseGltfScene(b.string()); });
    EXPECT_NE(error.find(b.string() + ": extensions.KHR_lights_punctual.lights[0]: color and intensity must be >= 0"),
              std::string::npos)
        << error;

    const fs::path c = freshTempDir("gltf-broken") / "broken.gltf";
    writeText(c, "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [");
    error = inputErrorOf([&] { parseGltfScene(c.string()); });
    EXPECT_NE(error.find("broken.gltf"), std::string::npos) << error;
}

// The image is 640 pixels on its longer side: a tall camera (the sweep's
// aspectRatio 0.01 made a 640 x 16384 image, 30 s and 929 MB) gets a tall,
// narrow image; one whose shorter side would be under a pixel is refused.
TEST(GltfScene, ExtremeAspectRatiosGiveSmallImagesOrAnError)
{
    auto cameraWithAspect = [](const std::string& aspect) {
        return R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1, "aspectRatio": )" +
               aspect + "}}]";
    };
    const std::string nodes =
        R"("scenes": [{"nodes": [0, 1]}], "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}])";
    const Scene tall = parseGltfScene(writeTriangle("gltf-tall", cameraWithAspect("0.01"), nodes).string());
    EXPECT_EQ(tall.camera.width, 6u);
    EXPECT_EQ(tall.camera.height, 640u);
    const Scene wide = parseGltfScene(writeTriangle("gltf-wide", cameraWithAspect("2"), nodes).string());
    EXPECT_EQ(wide.camera.width, 640u);
    EXPECT_EQ(wide.camera.height, 320u);
    for (const char* aspect : {"1e-300", "1e300"}) {
        const fs::path file = writeTriangle("gltf-thin", cameraWithAspect(aspect), nodes);
        const std::string error = inputErrorOf([&] { parseGltfScene(file.string()); });
        EXPECT_NE(error.find(file.string() + ": cameras[0]"), std::string::npos) << error;
        EXPECT_NE(error.find("less than one pixel"), std::string::npos) << error;
    }
    // A zero rotation quaternion on the camera's node is no rotation to repair.
    const fs::path zero = writeTriangle(
        "gltf-zero-rotation", cameraWithAspect("1.5"),
        R"("scenes": [{"nodes": [0, 1]}], "nodes": [{"mesh": 0}, {"camera": 0, "rotation": [0, 0, 0, 0]}])");
    const std::string error = inputErrorOf([&] { parseGltfScene(zero.string()); });
    EXPECT_NE(error.find("nodes[1].rotation: a rotation quaternion must not be zero"), std::string::npos) << error;
}

// The anisotropy test scene: six spheres whose materials carry the file's
// strengths and rotations, with the file's tangents, in the anisotropic kernel.
TEST(GltfScene, AnisotropySpheresCarryTheirStrengthsRotationsAndTangents)
{
    const Scene scene = parseGltfScene((kSource / "scenes/gltf/anisotropy-spheres.gltf").string());
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
    std::vector<std::pair<double, double>> layers;
    for (const Material& m : scene.materials) layers.emplace_back(m.layers.anisotropy, m.layers.anisotropyRotation);
    const double pi = glm::pi<double>();
    for (const auto& expected :
         std::vector<std::pair<double, double>>{{0.5, 0.0}, {1.0, 0.0}, {0.8, 0.0}, {0.8, pi / 4}, {0.8, pi / 2}}) {
        const bool found = std::any_of(layers.begin(), layers.end(), [&](const auto& l) {
            return std::abs(l.first - expected.first) < 1e-6 && std::abs(l.second - expected.second) < 1e-6;
        });
        EXPECT_TRUE(found) << "strength " << expected.first << ", rotation " << expected.second;
    }
    ASSERT_FALSE(scene.meshes.empty());
    EXPECT_FALSE(scene.meshes[0].geometry->data.tangents.empty()) << "the file's TANGENT";
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.has(PbrLobe::Anisotropy) && features.tangentFrames());
}

TEST(GltfScene, CamerasAreListedInFileOrderAndOrthographicOnesKeepTheirView)
{
    // Three cameras placed in reverse order by the nodes: --camera's list
    // still names them 0, 1, 2; an orthographic one is rendered as such.
    const std::string cameras = R"("cameras": [
        {"name": "front", "type": "perspective", "perspective": {"yfov": 0.5}},
        {"name": "side", "type": "perspective", "perspective": {"yfov": 0.6}},
        {"name": "plan", "type": "orthographic", "orthographic": {"xmag": 3, "ymag": 1.5, "znear": 0.1, "zfar": 9}}])";
    const fs::path file = writeTriangle("gltf-camera-order", cameras,
                                        R"("scenes": [{"nodes": [0, 1, 2, 3]}], "nodes": [{"mesh": 0},
                                           {"camera": 2, "translation": [0, 0, 5]},
                                           {"camera": 1, "translation": [0, 0, 6]},
                                           {"camera": 0, "translation": [0, 0, 7]}])");
    const std::string error = inputErrorOf([&] { parseGltfScene(file.string(), {std::string("top"), std::nullopt}); });
    EXPECT_NE(error.find("its cameras: 0 ('front'), 1 ('side'), 2 ('plan')"), std::string::npos) << error;
    const Scene plan = parseGltfScene(file.string(), {std::string("plan"), std::nullopt});
    EXPECT_EQ(plan.camera.orthographicHeight, 3.0);
    EXPECT_EQ(plan.camera.width, 640u);
    EXPECT_EQ(plan.camera.height, 320u); // xmag / ymag = 2
    EXPECT_TRUE(plan.warnings.empty());
    // Without --camera, the first camera the node walk meets: node 1's.
    EXPECT_TRUE(parseGltfScene(file.string()).camera.orthographic());
}

TEST(GltfScene, SpotAndRangeFromTheFile)
{
    const std::string spot = R"("extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "color": [1, 0.5, 0.25], "intensity": 8, "range": 10,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}]}})";
    const std::string nodes = R"("scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"translation": [0, 4, 0], "rotation": [-0.70710678118654752, 0, 0, 0.70710678118654752],
                   "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    const Scene scene = parseGltfScene(writeTriangle("gltf-spot", spot, nodes).string());
    ASSERT_EQ(scene.spotLights.size(), 1u);
    const SpotLight& s = scene.spotLights[0];
    expectNear(s.position, {0, 4, 0}, 1e-12, "position");
    expectNear(s.direction, {0, -1, 0}, 1e-12, "direction"); // -Z turned -90 degrees about x
    expectNear(s.intensity, {8, 4, 2}, 1e-12, "intensity");
    EXPECT_NEAR(s.innerConeAngle, glm::degrees(0.2), 1e-12);
    EXPECT_NEAR(s.outerConeAngle, glm::degrees(0.5), 1e-12);
    bool warned = false;
    for (const std::string& w : scene.warnings) warned = warned || w.find(".range: ignored") != std::string::npos;
    EXPECT_TRUE(warned);
    EXPECT_EQ(scene.background.color, Color(0.0)); // it has a light
}

TEST(GltfScene, ImportedIntoATomlSceneKeepsTheTomlCameraAndAddsLights)
{
    const fs::path dir = kSource / "scenes/gltf";
    const std::string text = "[camera]\neye = [0, 1, 9]\ntarget = [0, 1, 0]\nfov = 30\n"
                             "[import]\ngltf = \"lights-camera.gltf\"\n"
                             "[[lights]]\ntype = \"point\"\nposition = [0, 5, 0]\nintensity = 1\n";
    const Scene scene = parseSceneString(text, (dir / "import.toml").string());
    EXPECT_EQ(scene.camera.eye, glm::dvec3(0, 1, 9));
    const Scene gltf = parseGltfScene((dir / "lights-camera.gltf").string());
    EXPECT_EQ(scene.pointLights.size(), gltf.pointLights.size() + 1);
    EXPECT_EQ(scene.spotLights.size(), gltf.spotLights.size());
    EXPECT_EQ(scene.meshes.size(), gltf.meshes.size());
    // Without a [camera], the file's.
    const Scene own = parseSceneString("[import]\ngltf = \"lights-camera.gltf\"\n", (dir / "import.toml").string());
    EXPECT_EQ(own.camera.eye, gltf.camera.eye);
    // A missing file is the scene's error, located at the key.
    const std::string error =
        inputErrorOf([&] { parseSceneString("[import]\ngltf = \"missing.glb\"\n", (dir / "import.toml").string()); });
    EXPECT_NE(error.find("import.toml:2:8: import.gltf: file"), std::string::npos) << error;
}

} // namespace
} // namespace vkrt::test
