// Tests of the scene-file parser: valid files produce the expected Scene, and
// every kind of bad input produces a SceneError at the exact offending position.
#include "scene/FeatureSet.h"
#include "scene/SceneParser.h"

#include "scene/TomlTraps.h"
#include "util/Hash.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace vkrt {
namespace {

namespace fs = std::filesystem;

/// Creates a fresh directory under the system temp dir and removes it afterwards.
class TempDir {
public:
    TempDir()
    {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_path = fs::temp_directory_path() /
                 ("vkrt_scene_parser_" + std::string(info->test_suite_name()) + "_" + info->name());
        fs::remove_all(m_path);
        fs::create_directories(m_path);
    }
    ~TempDir()
    {
        std::error_code ignored;
        fs::remove_all(m_path, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const fs::path& path() const { return m_path; }

    fs::path write(const std::string& relative, const std::string& contents) const
    {
        const fs::path file = m_path / relative;
        fs::create_directories(file.parent_path());
        std::ofstream(file, std::ios::binary) << contents;
        return file;
    }

private:
    fs::path m_path;
};

/// Parses text that must be rejected and returns the error.
SceneError parseError(const std::string& text, const std::string& path = "scene.toml")
{
    try {
        parseSceneString(text, path);
    } catch (const SceneError& error) {
        return error;
    }
    ADD_FAILURE() << "expected a SceneError for:\n" << text;
    return SceneError({}, "");
}

void expectVec(const glm::dvec3& actual, const glm::dvec3& expected)
{
    EXPECT_DOUBLE_EQ(actual.x, expected.x);
    EXPECT_DOUBLE_EQ(actual.y, expected.y);
    EXPECT_DOUBLE_EQ(actual.z, expected.z);
}

const std::string kCamera = R"([camera]
eye = [0, 1, 5]
target = [0, 1, 0]
fov = 45
)";

// ---------------------------------------------------------------- valid files

const std::string kEverything = R"(# every shape, material and light type
[render]
integrator = "path"
max_depth = 12

[camera]
eye = [0, 2, 8]
target = [0, 1, 0]
up = [0, 2, 0]
fov = 40.5
width = 320
height = 200

[materials.red]
type = "lambert"
albedo = [0.8, 0.1, 0.1]

[materials.plastic]
type = "phong"
diffuse = 0.5
specular = [0.2, 0.3, 0.4]
shininess = 64

[materials.chrome]
type = "mirror"
reflectance = 0.9
fresnel = "schlick"
ior = 2.5

[materials.brushed]
type = "glossy"
exponent = 250
fresnel = "none"

[materials.glass]
type = "dielectric"
ior = 1.5
absorption = [0.1, 0, 2]
fresnel = "exact"

[[objects]]
shape = "sphere"
material = "glass"
center = [0, 1, 0]
radius = 1

[[objects]]
shape = "box"
material = "plastic"
min = [-1, 0, -1]
max = [1, 0.5, 1]

[[objects]]
shape = "triangle"
material = "chrome"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]

[[objects]]
shape = "plane"
material = "red"
point = [0, 0, 0]
normal = [0, 3, 4]

[[objects]]
shape = "sphere"
material = "brushed"
center = [2, 1, 0]
radius = 0.25

[[lights]]
type = "point"
position = [3, 5, 3]
intensity = [10, 20, 30]

[[lights]]
type = "triangle"
vertices = [[0, 4, 0], [1, 4, 0], [0, 4, 1]]
radiance = 5
two_sided = true

[background]
color = [0.1, 0.2, 0.3]
)";

TEST(SceneParserValid, EverythingIsParsed)
{
    const Scene scene = parseSceneString(kEverything, "dir/everything.toml");
    EXPECT_EQ(scene.path, "dir/everything.toml");
    EXPECT_EQ(scene.fileHash, fnv1a64(kEverything));
    EXPECT_EQ(scene.render.integrator, Integrator::Path);
    EXPECT_EQ(scene.render.maxDepth, 12);

    expectVec(scene.camera.eye, {0, 2, 8});
    expectVec(scene.camera.target, {0, 1, 0});
    expectVec(scene.camera.up, {0, 2, 0});
    EXPECT_DOUBLE_EQ(scene.camera.fovY, 40.5);
    EXPECT_EQ(scene.camera.width, 320u);
    EXPECT_EQ(scene.camera.height, 200u);

    expectVec(scene.background.color, {0.1, 0.2, 0.3});
    EXPECT_FALSE(scene.background.cubemap.has_value());
    EXPECT_EQ(scene.primitiveCount(), 5u);
}

TEST(SceneParserValid, MaterialsKeepFileOrderAndValues)
{
    const Scene scene = parseSceneString(kEverything, "everything.toml");
    ASSERT_EQ(scene.materials.size(), 5u);
    const std::vector<std::string> names{"red", "plastic", "chrome", "brushed", "glass"};
    for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(scene.materials[i].name, names[i]);

    const Material& red = scene.materials[0];
    EXPECT_EQ(red.type, MaterialType::Lambert);
    expectVec(red.diffuse, {0.8, 0.1, 0.1});
    EXPECT_EQ(red.where.str(), "everything.toml:14:1");

    const Material& plastic = scene.materials[1];
    EXPECT_EQ(plastic.type, MaterialType::Phong);
    expectVec(plastic.diffuse, {0.5, 0.5, 0.5});
    expectVec(plastic.specular, {0.2, 0.3, 0.4});
    EXPECT_DOUBLE_EQ(plastic.exponent, 64);

    const Material& chrome = scene.materials[2];
    EXPECT_EQ(chrome.type, MaterialType::Mirror);
    expectVec(chrome.specular, {0.9, 0.9, 0.9});
    EXPECT_EQ(chrome.fresnel, FresnelMode::Schlick);
    EXPECT_DOUBLE_EQ(chrome.ior, 2.5);

    const Material& brushed = scene.materials[3];
    EXPECT_EQ(brushed.type, MaterialType::Glossy);
    expectVec(brushed.specular, {1, 1, 1});
    EXPECT_DOUBLE_EQ(brushed.exponent, 250);
    EXPECT_EQ(brushed.fresnel, FresnelMode::None);
    EXPECT_DOUBLE_EQ(brushed.ior, 1.5);

    const Material& glass = scene.materials[4];
    EXPECT_EQ(glass.type, MaterialType::Dielectric);
    EXPECT_DOUBLE_EQ(glass.ior, 1.5);
    expectVec(glass.absorption, {0.1, 0, 2});
    EXPECT_EQ(glass.fresnel, FresnelMode::Exact);
}

TEST(SceneParserValid, PbrLayersAreReadWithTheExtensionsDefaults)
{
    const Scene scene = parseSceneString(kCamera + R"([materials.plain]
type = "pbr"
[materials.layered]
type = "pbr"
ior = 1.8
specular = 0.5
specular_color = [2, 1, 0.5]
sheen_color = [0.9, 0.4, 0.2]
sheen_roughness = 0.6
clearcoat = 1
clearcoat_roughness = 0.1
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "layered"
)",
                                         "layers.toml");
    const Material& plain = scene.materials.at(0);
    EXPECT_EQ(plain.layers, PbrLayers{});
    EXPECT_DOUBLE_EQ(plain.ior, 1.5);
    EXPECT_FALSE(plain.hasPbrLayers()) << "the defaults keep the plain kernel";
    const Material& layered = scene.materials.at(1);
    EXPECT_TRUE(layered.hasPbrLayers());
    EXPECT_DOUBLE_EQ(layered.ior, 1.8);
    EXPECT_DOUBLE_EQ(layered.layers.specular, 0.5);
    expectVec(layered.layers.specularColor, {2, 1, 0.5});
    expectVec(layered.layers.sheenColor, {0.9, 0.4, 0.2});
    EXPECT_DOUBLE_EQ(layered.layers.sheenRoughness, 0.6);
    EXPECT_DOUBLE_EQ(layered.layers.clearcoat, 1.0);
    EXPECT_DOUBLE_EQ(layered.layers.clearcoatRoughness, 0.1);
    EXPECT_TRUE(featuresOf(scene).pbrLayers);
}

TEST(SceneParserValid, PbrTransmissionAndIridescenceAreRead)
{
    const Scene scene = parseSceneString(kCamera + R"([materials.window]
type = "pbr"
transmission = 0.5
[materials.water]
type = "pbr"
transmission = 1
thin_walled = false
ior = 1.33
attenuation_color = [0.5, 1, 0.25]
attenuation_distance = 2
[materials.bubble]
type = "pbr"
iridescence = 1
iridescence_ior = 1.4
iridescence_thickness = 550
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "window"
[[objects]]
shape = "sphere"
center = [3, 0, 0]
radius = 1
material = "water"
[[objects]]
shape = "sphere"
center = [6, 0, 0]
radius = 1
material = "bubble"
)",
                                         "transmission.toml");
    const Material& window = scene.materials.at(0);
    EXPECT_DOUBLE_EQ(window.layers.transmission, 0.5);
    EXPECT_TRUE(window.layers.thinWalled) << "glTF's default without a volume";
    EXPECT_FALSE(window.layers.volumetric());
    const Material& water = scene.materials.at(1);
    EXPECT_TRUE(water.layers.volumetric());
    EXPECT_DOUBLE_EQ(water.ior, 1.33);
    // attenuation_color reached after attenuation_distance: sigma = -ln(c) / d.
    EXPECT_NEAR(water.absorption.r, std::log(2.0) / 2.0, 1e-12);
    EXPECT_EQ(water.absorption.g, 0.0);
    EXPECT_NEAR(water.absorption.b, std::log(4.0) / 2.0, 1e-12);
    const Material& bubble = scene.materials.at(2);
    EXPECT_DOUBLE_EQ(bubble.layers.iridescence, 1.0);
    EXPECT_DOUBLE_EQ(bubble.layers.iridescenceIor, 1.4);
    EXPECT_DOUBLE_EQ(bubble.layers.iridescenceThicknessMax, 550.0);
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.pbrLayers && features.has(PbrLobe::Transmission) && features.has(PbrLobe::Iridescence));
}

TEST(SceneParserValid, PbrAnisotropyIsReadInDegreesAndTurnsOnItsVariant)
{
    const Scene scene = parseSceneString(kCamera + R"([materials.brushed]
type = "pbr"
roughness = 0.3
anisotropy = 0.7
anisotropy_rotation = 90
[materials.plain]
type = "pbr"
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "brushed"
)",
                                         "anisotropy.toml");
    const Material& brushed = scene.materials.at(0);
    EXPECT_DOUBLE_EQ(brushed.layers.anisotropy, 0.7);
    EXPECT_NEAR(brushed.layers.anisotropyRotation, std::numbers::pi / 2.0, 1e-15);
    EXPECT_TRUE(brushed.pbrAnisotropic() && brushed.hasPbrLayers());
    EXPECT_FALSE(scene.materials.at(1).hasPbrLayers());
    // The lobe turns with the hit's tangent frame, which the textured variants compute.
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.has(PbrLobe::Anisotropy) && features.textures && features.tangentFrames());
}

TEST(SceneParserValid, ShapesReferToMaterialIndices)
{
    const Scene scene = parseSceneString(kEverything);
    ASSERT_EQ(scene.spheres.size(), 2u);
    expectVec(scene.spheres[0].center, {0, 1, 0});
    EXPECT_DOUBLE_EQ(scene.spheres[0].radius, 1);
    EXPECT_EQ(scene.spheres[0].material, 4u); // glass
    EXPECT_DOUBLE_EQ(scene.spheres[1].radius, 0.25);
    EXPECT_EQ(scene.spheres[1].material, 3u); // brushed

    ASSERT_EQ(scene.boxes.size(), 1u);
    expectVec(scene.boxes[0].min, {-1, 0, -1});
    expectVec(scene.boxes[0].max, {1, 0.5, 1});
    EXPECT_EQ(scene.boxes[0].material, 1u); // plastic

    ASSERT_EQ(scene.triangles.size(), 1u);
    expectVec(scene.triangles[0].vertices[1], {1, 0, 0});
    EXPECT_EQ(scene.triangles[0].material, 2u); // chrome

    ASSERT_EQ(scene.planes.size(), 1u);
    expectVec(scene.planes[0].normal, {0, 0.6, 0.8}); // normalized from [0, 3, 4]
    EXPECT_EQ(scene.planes[0].material, 0u);          // red
}

TEST(SceneParserValid, Lights)
{
    const Scene scene = parseSceneString(kEverything);
    ASSERT_EQ(scene.pointLights.size(), 1u);
    expectVec(scene.pointLights[0].position, {3, 5, 3});
    expectVec(scene.pointLights[0].intensity, {10, 20, 30});
    ASSERT_EQ(scene.triangleLights.size(), 1u);
    expectVec(scene.triangleLights[0].vertices[2], {0, 4, 1});
    expectVec(scene.triangleLights[0].radiance, {5, 5, 5});
    EXPECT_TRUE(scene.triangleLights[0].twoSided);
}

TEST(SceneParserValid, DefaultsForMinimalScene)
{
    const Scene scene = parseSceneString(kCamera);
    EXPECT_EQ(scene.path, "<string>");
    EXPECT_EQ(scene.render.integrator, Integrator::Whitted);
    EXPECT_EQ(scene.render.maxDepth, 5);
    expectVec(scene.camera.up, {0, 1, 0});
    EXPECT_EQ(scene.camera.width, 640u);
    EXPECT_EQ(scene.camera.height, 480u);
    expectVec(scene.background.color, {0, 0, 0});
    EXPECT_FALSE(scene.background.cubemap.has_value());
    EXPECT_TRUE(scene.materials.empty());
    EXPECT_EQ(scene.primitiveCount(), 0u);
    EXPECT_TRUE(scene.pointLights.empty());
    EXPECT_TRUE(scene.triangleLights.empty());
}

TEST(SceneParserValid, MaterialDefaults)
{
    const Scene scene = parseSceneString(kCamera + R"(
[materials.l]
type = "lambert"
[materials.p]
type = "phong"
[materials.m]
type = "mirror"
[materials.g]
type = "glossy"
[materials.d]
type = "dielectric"
)");
    ASSERT_EQ(scene.materials.size(), 5u);
    expectVec(scene.materials[0].diffuse, {0.8, 0.8, 0.8});
    expectVec(scene.materials[1].diffuse, {0.8, 0.8, 0.8});
    expectVec(scene.materials[1].specular, {0, 0, 0});
    EXPECT_DOUBLE_EQ(scene.materials[1].exponent, 32);
    expectVec(scene.materials[2].specular, {1, 1, 1});
    EXPECT_EQ(scene.materials[2].fresnel, FresnelMode::None);
    EXPECT_DOUBLE_EQ(scene.materials[2].ior, 1.5);
    EXPECT_DOUBLE_EQ(scene.materials[3].exponent, 100);
    EXPECT_EQ(scene.materials[3].fresnel, FresnelMode::None);
    EXPECT_DOUBLE_EQ(scene.materials[4].ior, 1.5);
    expectVec(scene.materials[4].absorption, {0, 0, 0});
    EXPECT_EQ(scene.materials[4].fresnel, FresnelMode::Default);
}

TEST(SceneParserValid, MaterialsInFileOrderNotAlphabetical)
{
    const Scene scene = parseSceneString(kCamera + R"(
[materials]
zeta = { type = "lambert" }
alpha = { type = "mirror" }
mid.type = "phong"

[[objects]]
shape = "sphere"
material = "alpha"
center = [0, 0, 0]
radius = 1
)");
    ASSERT_EQ(scene.materials.size(), 3u);
    EXPECT_EQ(scene.materials[0].name, "zeta");
    EXPECT_EQ(scene.materials[1].name, "alpha");
    EXPECT_EQ(scene.materials[2].name, "mid");
    ASSERT_EQ(scene.spheres.size(), 1u);
    EXPECT_EQ(scene.spheres[0].material, 1u);
}

TEST(SceneParserValid, ExtremeButLegalValues)
{
    const Scene scene = parseSceneString(R"([camera]
eye = [1e308, 0, 0]
target = [-1e308, 0, 0]
fov = 179.9
width = 16384
height = 4096

[materials.m]
type = "dielectric"
ior = 1e30
absorption = 1e20

[[objects]]
shape = "sphere"
material = "m"
center = [1e30, -1e30, 1e30]
radius = 1e30

[[objects]]
shape = "triangle"
material = "m"
vertices = [[1, 1, 1], [1, 1, 1], [2, 2, 2]]

[[objects]]
shape = "plane"
material = "m"
point = [0, 0, 0]
normal = [1e-300, 0, 0]

[[lights]]
type = "point"
position = [1e30, 1e30, 1e30]
intensity = 1e20

[[lights]]
type = "triangle"
vertices = [[0, 0, 0], [0, 0, 0], [0, 0, 0]]
radiance = [0, 0, 0]
)");
    EXPECT_EQ(scene.camera.width * uint64_t{scene.camera.height}, SceneLimits::maxImagePixels);
    EXPECT_DOUBLE_EQ(scene.materials[0].ior, 1e30);
    EXPECT_DOUBLE_EQ(scene.spheres[0].radius, 1e30);
    ASSERT_EQ(scene.triangles.size(), 1u); // degenerate triangles are the renderer's business
    expectVec(scene.planes[0].normal, {1, 0, 0});
    expectVec(scene.pointLights[0].intensity, {1e20, 1e20, 1e20});
    EXPECT_EQ(scene.triangleLights.size(), 1u);
    EXPECT_FALSE(scene.triangleLights[0].twoSided);
}

TEST(SceneParserValid, IntegersAcceptedForFloatsAndGreyColours)
{
    const Scene scene = parseSceneString(kCamera + R"(
[materials.grey]
type = "lambert"
albedo = 1
[background]
color = 2
)");
    EXPECT_DOUBLE_EQ(scene.camera.fovY, 45);
    expectVec(scene.materials[0].diffuse, {1, 1, 1});
    expectVec(scene.background.color, {2, 2, 2});
}

TEST(SceneParserValid, FovDefaultsTo45Degrees)
{
    const Scene scene = parseSceneString("[camera]\neye = [0, 1, 5]\ntarget = [0, 1, 0]\nfov = 30\n");
    EXPECT_DOUBLE_EQ(scene.camera.fovY, 30);
    const Scene defaulted = parseSceneString("[camera]\neye = [0, 1, 5]\ntarget = [0, 1, 0]\n");
    EXPECT_DOUBLE_EQ(defaulted.camera.fovY, 45);
}

TEST(SceneParserValid, UnusedMaterialIsFine)
{
    const Scene scene = parseSceneString(kCamera + "[materials.unused]\ntype = \"mirror\"\n");
    EXPECT_EQ(scene.materials.size(), 1u);
}

TEST(SceneParserValid, CubemapFacesResolvedAgainstSceneDirectory)
{
    TempDir dir;
    const std::vector<std::string> faces{"px.exr", "nx.exr", "py.png", "ny.png", "pz.EXR"};
    for (const std::string& face : faces) dir.write("sky/" + face, "x");
    const fs::path absolute = dir.write("elsewhere/nz.exr", "x");
    const std::string text = kCamera + R"(
[background.cubemap]
px = "sky/px.exr"
nx = "sky/nx.exr"
py = "sky/py.png"
ny = "sky/ny.png"
pz = "sky/pz.EXR"
nz = ")" + absolute.string() +
                             "\"\n";
    const fs::path scenePath = dir.write("scene.toml", text);

    const Scene scene = parseSceneFile(scenePath.string());
    ASSERT_TRUE(scene.background.cubemap.has_value());
    const Cubemap& cubemap = *scene.background.cubemap;
    for (size_t i = 0; i < faces.size(); ++i)
        EXPECT_TRUE(fs::equivalent(cubemap.facePaths[i], dir.path() / "sky" / faces[i])) << cubemap.facePaths[i];
    EXPECT_EQ(cubemap.facePaths[5], absolute.string());
    EXPECT_EQ(cubemap.where.line, 6);
    EXPECT_EQ(cubemap.where.column, 1);
    EXPECT_EQ(scene.fileHash, fnv1a64(text));
    expectVec(scene.background.color, {0, 0, 0});
}

TEST(SceneParserValid, FileAndStringAgree)
{
    TempDir dir;
    const fs::path file = dir.write("everything.toml", kEverything);
    const Scene fromFile = parseSceneFile(file.string());
    const Scene fromString = parseSceneString(kEverything, file.string());
    EXPECT_EQ(fromFile.path, file.string());
    EXPECT_EQ(fromFile.fileHash, fromString.fileHash);
    EXPECT_EQ(fromFile.materials.size(), fromString.materials.size());
    EXPECT_EQ(fromFile.primitiveCount(), fromString.primitiveCount());
}

// ------------------------------------------------------------ unreadable file

TEST(SceneParserFile, MissingFileIsInputErrorNamingPathAndReason)
{
    const std::string path = (fs::temp_directory_path() / "vkrt_no_such_dir" / "missing.toml").string();
    try {
        parseSceneFile(path);
        FAIL() << "expected InputError";
    } catch (const SceneError&) {
        FAIL() << "an unreadable file is not a SceneError";
    } catch (const InputError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
    }
}

TEST(SceneParserFile, DirectoryIsInputError)
{
    TempDir dir;
    EXPECT_THROW(parseSceneFile(dir.path().string()), InputError);
}

// ----------------------------------------------------------------- bad inputs

struct BadScene {
    std::string name;
    std::string text;
    int line;
    int column;
    std::string fragment;
};

std::ostream& operator<<(std::ostream& out, const BadScene& bad) { return out << bad.name; }

class SceneParserBad : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneParserBad, ReportsMessageAndPosition)
{
    const BadScene& bad = GetParam();
    const SceneError error = parseError(bad.text);
    const std::string message = error.what();
    EXPECT_NE(message.find(bad.fragment), std::string::npos) << "message: " << message;
    EXPECT_EQ(error.where().file, "scene.toml");
    EXPECT_EQ(error.where().line, bad.line) << message;
    EXPECT_EQ(error.where().column, bad.column) << message;
    EXPECT_EQ(message.rfind(error.where().str() + ": ", 0), 0u) << message;
}

/// "a.a.a...": a dotted key of `parts` parts.
std::string repeatedParts(int parts)
{
    std::string key = "a";
    for (int i = 1; i < parts; ++i) key += ".a";
    return key;
}

// kCamera occupies lines 1-4, so text appended to it starts on line 5.
const std::vector<BadScene> kBadScenes = {
    {"SyntaxError", kCamera + "width = 640 480\n", 5, 13, "invalid TOML: "},
    {"SyntaxErrorUnclosedArray", "[camera]\neye = [0, 1, 5\nfov = 45\n", 3, 1,
     "invalid TOML: Error while parsing array: expected comma or closing ']'"},
    {"UnknownKeySuggestion", kCamera + "fvo = 45\n", 5, 1, "camera: unknown key 'fvo'; did you mean 'fov'?"},
    {"UnknownKeyCaseInsensitive", kCamera + "WIDTH = 45\n", 5, 1, "unknown key 'WIDTH'; did you mean 'width'?"},
    {"UnknownKeyNoSuggestion", kCamera + "zoom = 2\n", 5, 1, "camera: unknown key 'zoom'"},
    {"UnknownTopLevelTable", kCamera + "[camra]\n", 5, 2, "unknown top-level table 'camra'; did you mean 'camera'?"},
    {"UnknownTopLevelKey", "title = 1\n" + kCamera, 1, 1, "unknown top-level key 'title'"},
    {"UnknownMaterialType", kCamera + "[materials.red]\ntype = \"lambret\"\n", 6, 8,
     "materials.red.type: unknown material type 'lambret'; did you mean 'lambert'?"},
    {"RoughnessAboveOne", kCamera + "[materials.m]\ntype = \"conductor\"\nroughness = 1.5\n", 7, 13,
     "materials.m.roughness: must be in [0, 1]"},
    {"RoughnessNegative", kCamera + "[materials.m]\ntype = \"plastic\"\nroughness = -0.1\n", 7, 13,
     "materials.m.roughness: must be in [0, 1]"},
    {"UnknownMetal", kCamera + "[materials.m]\ntype = \"conductor\"\nmetal = \"Gold\"\n", 7, 9,
     "materials.m.metal: unknown metal 'Gold'"},
    {"UnknownMetalSuggestion", kCamera + "[materials.m]\ntype = \"conductor\"\nmetal = \"Cuu\"\n", 7, 9,
     "unknown metal 'Cuu'; did you mean 'Cu'?"},
    {"MetalAndEta", kCamera + "[materials.m]\ntype = \"conductor\"\nmetal = \"Au\"\neta = 1\nk = 2\n", 8, 7,
     "give either 'metal' or 'eta' and 'k', not both"},
    {"EtaWithoutK", kCamera + "[materials.m]\ntype = \"conductor\"\neta = 1\n", 5, 1,
     "a conductor with 'eta' needs 'k' too"},
    {"AnisotropyOne", kCamera + "[materials.m]\ntype = \"conductor\"\nanisotropy = 1\n", 7, 14,
     "materials.m.anisotropy: must be in [0, 1)"},
    {"PlasticIorOne", kCamera + "[materials.m]\ntype = \"plastic\"\nior = 1\n", 7, 7, "must differ from 1"},
    {"MetallicAboveOne", kCamera + "[materials.m]\ntype = \"pbr\"\nmetallic = 2\n", 7, 12,
     "materials.m.metallic: must be in [0, 1]"},
    {"SheenColorAboveOne", kCamera + "[materials.m]\ntype = \"pbr\"\nsheen_color = 2\n", 7, 15,
     "materials.m.sheen_color"},
    {"ClearcoatNegative", kCamera + "[materials.m]\ntype = \"pbr\"\nclearcoat = -0.5\n", 7, 13,
     "materials.m.clearcoat: must be in [0, 1]"},
    {"SpecularColorNegative", kCamera + "[materials.m]\ntype = \"pbr\"\nspecular_color = [1, -1, 1]\n", 7, 22,
     "materials.m.specular_color[1]: must be >= 0"},
    {"KeyOfOtherMaterialType", kCamera + "[materials.red]\ntype = \"lambert\"\nshininess = 3\n", 7, 1,
     "materials.red: key 'shininess' is not used by material type 'lambert'"},
    {"LambertRejectsFresnel", kCamera + "[materials.red]\ntype = \"lambert\"\nfresnel = \"schlick\"\n", 7, 1,
     "key 'fresnel' is not used by material type 'lambert'"},
    {"MaterialMissingType", kCamera + "[materials.red]\nalbedo = 1\n", 5, 1,
     "materials.red: missing required key 'type'"},
    {"UnknownMaterialName",
     kCamera + "[materials.red]\ntype = \"lambert\"\n[[objects]]\nshape = \"plane\"\nmaterial = \"rde\"\n"
               "point = [0, 0, 0]\nnormal = [0, 1, 0]\n",
     9, 12, "objects[0].material: unknown material 'rde'; did you mean 'red'?"},
    {"UnknownMaterialNoneDefined",
     kCamera + "[[objects]]\nshape = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1\n", 7, 12,
     "unknown material 'red' (no materials are defined"},
    {"UnknownShape", kCamera + "[[objects]]\nshape = \"spere\"\n", 6, 9,
     "objects[0].shape: unknown shape 'spere'; did you mean 'sphere'?"},
    {"KeyOfOtherShape",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"box\"\nmaterial = \"m\"\nradius = 1\n", 10, 1,
     "objects[0]: key 'radius' is not used by shape 'box'"},
    {"MissingShape", kCamera + "[[objects]]\nmaterial = \"m\"\n", 5, 1, "objects[0]: missing required key 'shape'"},
    {"ObjectsNotAnArray", kCamera + "[objects]\nshape = \"sphere\"\n", 5, 1,
     "objects: expected an array of tables ([[objects]]), got a table"},
    {"MissingCamera", "[render]\nmax_depth = 3\n", 1, 1, "missing required table [camera]"},
    {"CameraNotATable", "camera = 3\n", 1, 10, "camera: expected a table, got an integer"},
    {"MissingTarget", "[camera]\neye = [0, 1, 5]\nfov = 45\n", 1, 1, "camera: missing required key 'target'"},
    {"MissingEyeDottedCamera", "\ncamera.fov = 45\n", 2, 1, "camera: missing required key 'eye'"},
    {"WrongTypeString", "[camera]\neye = [0, 1, 5]\ntarget = [0, 1, 0]\nfov = \"45\"\n", 4, 7,
     "camera.fov: expected a number, got a string"},
    {"WrongTypeElement", "[camera]\neye = [0, true, 5]\n", 2, 11, "camera.eye[1]: expected a number, got a boolean"},
    {"WrongArrayLength", "[camera]\neye = [0, 1]\n", 2, 7,
     "camera.eye: expected an array of 3 numbers, got 2 element(s)"},
    {"VectorNotArray", "[camera]\neye = 5\n", 2, 7, "camera.eye: expected an array of 3 numbers, got an integer"},
    {"NaN", "[camera]\neye = [0, nan, 5]\n", 2, 11, "camera.eye[1]: must be finite, got nan"},
    {"Inf",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
               "center = [0, 0, 0]\nradius = inf\n",
     11, 10, "objects[0].radius: must be finite, got inf"},
    {"NegativeInfColour", kCamera + "[background]\ncolor = [0, -inf, 0]\n", 6, 13,
     "background.color[1]: must be finite, got -inf"},
    {"NegativeRadius",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
               "center = [0, 0, 0]\nradius = -1\n",
     11, 10, "objects[0].radius: must be > 0, got -1"},
    {"ZeroRadius",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"sphere\"\nmaterial = \"m\"\n"
               "center = [0, 0, 0]\nradius = 0\n",
     11, 10, "objects[0].radius: must be > 0, got 0"},
    {"EyeEqualsTarget", "[camera]\neye = [1, 2, 3]\ntarget = [1, 2, 3]\nfov = 45\n", 3, 10,
     "camera.target: must differ from camera.eye"},
    {"ZeroLengthUp", kCamera + "up = [0, 0, 0]\n", 5, 6, "camera.up: must not be zero-length"},
    {"UpParallelToView", kCamera + "up = [0, 0, -2]\n", 5, 6, "camera.up: must not be parallel to the view direction"},
    {"DefaultUpParallelToView", "[camera]\neye = [0, 5, 0]\ntarget = [0, 0, 0]\nfov = 45\n", 1, 1,
     "camera: the default up [0, 1, 0] is parallel to the view direction"},
    {"FovZero", "[camera]\neye = [0, 1, 5]\ntarget = [0, 1, 0]\nfov = 0\n", 4, 7,
     "camera.fov: must be strictly between 0 and 180 degrees, got 0"},
    {"Fov180", "[camera]\neye = [0, 1, 5]\ntarget = [0, 1, 0]\nfov = 180\n", 4, 7,
     "camera.fov: must be strictly between 0 and 180 degrees, got 180"},
    {"WidthZero", kCamera + "width = 0\n", 5, 9, "camera.width: must be between 1 and 16384, got 0"},
    {"HeightAboveSideLimit", kCamera + "height = 16385\n", 5, 10,
     "camera.height: must be between 1 and 16384, got 16385"},
    {"WidthNotInteger", kCamera + "width = 640.0\n", 5, 9, "camera.width: expected an integer, got a float"},
    {"TooManyPixels", kCamera + "width = 16384\nheight = 8192\n", 6, 10,
     "camera.height: width * height = 134217728 pixels exceeds the limit of 67108864"},
    {"AlbedoAboveOne", kCamera + "[materials.red]\ntype = \"lambert\"\nalbedo = [0.5, 1.5, 0]\n", 7, 16,
     "materials.red.albedo[1]: must be in [0, 1], got 1.5"},
    {"GreyAlbedoNegative", kCamera + "[materials.red]\ntype = \"lambert\"\nalbedo = -0.5\n", 7, 10,
     "materials.red.albedo: must be in [0, 1], got -0.5"},
    {"ColourAsString", kCamera + "[materials.red]\ntype = \"lambert\"\nalbedo = \"red\"\n", 7, 10,
     "materials.red.albedo: expected a colour (a number or an array of 3 numbers), got a string"},
    {"IorBelowOne", kCamera + "[materials.glass]\ntype = \"dielectric\"\nior = 0.9\n", 7, 7,
     "materials.glass.ior: must be >= 1, got 0.9"},
    {"IorAboveLimit", kCamera + "[materials.glass]\ntype = \"dielectric\"\nior = 1e31\n", 7, 7,
     "materials.glass.ior: must be <= 1e+30, got 1e+31"},
    {"NegativeAbsorption", kCamera + "[materials.glass]\ntype = \"dielectric\"\nabsorption = [0, 0, -1]\n", 7, 21,
     "materials.glass.absorption[2]: must be >= 0, got -1"},
    {"DielectricFresnelNone", kCamera + "[materials.glass]\ntype = \"dielectric\"\nfresnel = \"none\"\n", 7, 11,
     "unknown fresnel mode 'none' (expected one of: schlick, exact)"},
    {"NegativeShininess", kCamera + "[materials.p]\ntype = \"phong\"\nshininess = -1\n", 7, 13,
     "materials.p.shininess: must be >= 0, got -1"},
    {"QuotedMaterialNameInPath", kCamera + "[materials.\"my glass\"]\ntype = \"glass\"\n", 6, 8,
     "materials.\"my glass\".type: unknown material type 'glass'"},
    {"BoxMinNotBelowMax",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"box\"\nmaterial = \"m\"\n"
               "min = [0, 1, 0]\nmax = [1, 1, 1]\n",
     11, 7, "objects[0].max: must be greater than min in every component, but y: min = 1 >= max = 1"},
    {"PlaneZeroNormal",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"plane\"\nmaterial = \"m\"\n"
               "point = [0, 1, 0]\nnormal = [0, 0, 0]\n",
     11, 10, "objects[0].normal: must not be zero-length"},
    {"TriangleTwoVertices",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"triangle\"\nmaterial = \"m\"\n"
               "vertices = [[0, 0, 0], [1, 0, 0]]\n",
     10, 12, "objects[0].vertices: expected an array of 3 points, got 2 element(s)"},
    {"TriangleVertexTooShort",
     kCamera + "[materials.m]\ntype = \"mirror\"\n[[objects]]\nshape = \"triangle\"\nmaterial = \"m\"\n"
               "vertices = [[0, 0, 0], [1, 0, 0], [0, 1]]\n",
     10, 35, "objects[0].vertices[2]: expected an array of 3 numbers, got 2 element(s)"},
    {"UnknownLightType", kCamera + "[[lights]]\ntype = \"spto\"\n", 6, 8,
     "lights[0].type: unknown light type 'spto'; did you mean 'spot'?"},
    {"UnknownLightTypeListsTheKinds", kCamera + "[[lights]]\ntype = \"laser\"\n", 6, 8,
     "lights[0].type: unknown light type 'laser' (expected one of: point, triangle, directional, spot)"},
    {"PointLightMissingIntensity", kCamera + "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\n", 5, 1,
     "lights[0]: missing required key 'intensity'"},
    {"NegativeIntensity", kCamera + "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = -1\n", 8, 13,
     "lights[0].intensity: must be >= 0, got -1"},
    {"TwoSidedNotBool",
     kCamera + "[[lights]]\ntype = \"triangle\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nradiance = 1\n"
               "two_sided = \"yes\"\n",
     9, 13, "lights[0].two_sided: expected a boolean"},
    {"ColorPlusCubemap", kCamera + "[background]\ncolor = 0.5\n[background.cubemap]\npx = \"a.exr\"\n", 7, 1,
     "background.cubemap: cannot be combined with background.color (line 6)"},
    {"MaxDepthZero", "[render]\nmax_depth = 0\n" + kCamera, 2, 13, "render.max_depth: must be between 1 and 64, got 0"},
    {"MaxDepthTooLarge", "[render]\nmax_depth = 65\n" + kCamera, 2, 13,
     "render.max_depth: must be between 1 and 64, got 65"},
    {"InvalidUtf8InComment", kCamera + "# caf\xE9\n", 5, 6, "invalid TOML: invalid UTF-8 (byte 0xE9)"},
    {"InvalidUtf8InString",
     kCamera + "[materials.\"r\xC3\xA9"
               "d\xFF\"]\n",
     5, 16, "invalid TOML: invalid UTF-8 (byte 0xFF)"},
    {"UnknownIntegrator", "[render]\nintegrator = \"pathh\"\n" + kCamera, 2, 14,
     "render.integrator: unknown integrator 'pathh'; did you mean 'path'?"},
    // Colours go to the GPU as 32-bit floats, where 1e308 was infinite (issue 26).
    {"IntensityBeyondFloat",
     kCamera + "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 1e308, 1]\n", 8, 17,
     "lights[0].intensity[1]: must be at most 3.4e38 (the largest 32-bit float; vkrt renders with those), got 1e+308"},
    {"BackgroundBeyondFloat", kCamera + "[background]\ncolor = 3.5e38\n", 6, 9,
     "background.color: must be at most 3.4e38"},
    // Issue 28: the thin lens, suns, spots and lat-long maps.
    {"NegativeAperture", kCamera + "aperture_radius = -0.1\n", 5, 19, "camera.aperture_radius: must be >= 0, got -0.1"},
    // Issue 43: what the kernel's float32 holds (a focus at 1e20 rendered black).
    {"FocusBeyondTheKernelsFloats", kCamera + "aperture_radius = 0.1\nfocus_distance = 1e20\n", 1, 1,
     "camera: focus_distance: must be positive and at most 1e+18, got 1e+20"},
    {"ApertureBeyondTheKernelsFloats", kCamera + "aperture_radius = 1e300\n", 1, 1,
     "camera: aperture_radius: must be between 0 and 1e+18, got 1e+300"},
    {"TextureScaleBeyondTheKernelsFloats",
     kCamera + "[materials.m]\ntype = \"lambert\"\nalbedo = { texture = \"a.png\", scale = [1e39, 1] }\n", 7, 40,
     "materials.m.albedo.scale[0]: must be at most 1e+18 in magnitude"},
    {"ZeroFocusDistance", kCamera + "focus_distance = 0\n", 5, 18, "camera.focus_distance: must be > 0, got 0"},
    {"SunWithoutDirection", kCamera + "[[lights]]\ntype = \"directional\"\ndirection = [0, 0, 0]\nirradiance = 1\n", 7,
     13, "lights[0].direction: must not be zero-length"},
    {"SunWiderThanAHemisphere",
     kCamera + "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = 1\nangle = 180\n", 9, 9,
     "lights[0].angle: must be in [0, 180)"},
    {"SunTooSmallAndBright",
     kCamera + "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = 1e30\nangle = 1e-9\n", 9, 9,
     "beyond 32-bit float range"},
    {"SpotInnerBeyondOuter",
     kCamera + "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nintensity = 1\n"
               "inner_cone_angle = 50\nouter_cone_angle = 40\n",
     10, 20, "lights[0].inner_cone_angle: must not exceed outer_cone_angle (40)"},
    {"SpotWithoutCone",
     kCamera + "[[lights]]\ntype = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\nintensity = 1\n"
               "outer_cone_angle = 0\n",
     10, 20, "lights[0].outer_cone_angle: must be in (0, 90]"},
    {"EnvironmentNotLatLongFile", kCamera + "[background.environment]\nfile = \"sky.png\"\n", 6, 8,
     "background.environment.file: an environment map must be a lat-long .exr or .hdr file, got 'sky.png'"},
    {"EnvironmentFileMissing", kCamera + "[background.environment]\nfile = \"missing.hdr\"\n", 6, 8,
     "background.environment.file: file 'missing.hdr' does not exist"},
    {"EnvironmentPlusColor", kCamera + "[background]\ncolor = 0.5\n[background.environment]\nfile = \"a.exr\"\n", 7, 1,
     "background.environment: cannot be combined with background.color (line 6)"},
    {"EnvironmentRotateWithoutAxis", kCamera + "[background.environment]\nfile = \"a.exr\"\nrotate = { angle = 30 }\n",
     7, 10, "background.environment.rotate: missing required key 'axis'"},
    {"PbrThinWalledWithoutTransmission", kCamera + "[materials.g]\ntype = \"pbr\"\nthin_walled = false\n", 7, 15,
     "materials.g.thin_walled: applies to a transmitting material"},
    {"PbrAttenuationOnAThinWall",
     kCamera + "[materials.g]\ntype = \"pbr\"\ntransmission = 1\nattenuation_distance = 2\n", 8, 24,
     "materials.g.attenuation_distance: absorbs inside a volume: needs transmission above 0 and thin_walled = false"},
    {"PbrAbsorptionTwice",
     kCamera + "[materials.g]\ntype = \"pbr\"\ntransmission = 1\nthin_walled = false\nabsorption = 1\n"
               "attenuation_color = 0.5\n",
     9, 14, "materials.g.absorption: give the absorption either as `absorption` or as attenuation_color"},
    {"PbrIridescenceRangeWithoutTexture",
     kCamera + "[materials.g]\ntype = \"pbr\"\niridescence_thickness = 300\niridescence_thickness_range = [1, 2]\n", 8,
     31, "materials.g.iridescence_thickness_range: applies to a textured iridescence_thickness"},
    {"PbrAnisotropyAboveOne", kCamera + "[materials.g]\ntype = \"pbr\"\nanisotropy = 1.5\n", 7, 14,
     "materials.g.anisotropy: must be in [0, 1]"},
    {"PbrAnisotropyTextureWithoutStrength",
     kCamera + "[materials.g]\ntype = \"pbr\"\nanisotropy_texture = { texture = \"d.png\" }\n", 7, 22,
     "materials.g.anisotropy_texture: applies to an anisotropic material: set anisotropy above 0"},
    {"PbrCoatNormalMapWithoutCoat",
     kCamera + "[materials.g]\ntype = \"pbr\"\nclearcoat_normal_map = { texture = \"n.png\" }\n", 7, 24,
     "materials.g.clearcoat_normal_map: applies to a coated material: set clearcoat above 0"},
    {"PbrCoatNormalMapNotATable",
     kCamera + "[materials.g]\ntype = \"pbr\"\nclearcoat = 1\nclearcoat_normal_map = \"n.png\"\n", 8, 24,
     "materials.g.clearcoat_normal_map: expected a texture table"},
    {"DeepTomlNesting", kCamera + "[" + repeatedParts(20000) + "]\n", 5, 257,
     "invalid TOML: tables and arrays nest more than 128 levels deep here"},
};

INSTANTIATE_TEST_SUITE_P(AllCases, SceneParserBad, ::testing::ValuesIn(kBadScenes),
                         [](const ::testing::TestParamInfo<BadScene>& info) { return info.param.name; });

TEST(SceneParserSuggestions, OnlyCloseNamesAreSuggested)
{
    EXPECT_EQ(parseError(kCamera + "zoom = 2\n").message(), "camera: unknown key 'zoom'");
    // 'x' is within distance 2 of 'up', but replacing every letter is no hint.
    EXPECT_EQ(parseError(kCamera + "x = 2\n").message(), "camera: unknown key 'x'");
    EXPECT_EQ(parseError(kCamera + "eyes = 2\n").message(), "camera: unknown key 'eyes'; did you mean 'eye'?");
    EXPECT_EQ(parseError(kCamera + "Target = 2\n").message(), "camera: unknown key 'Target'; did you mean 'target'?");
}

TEST(SceneParserSuggestions, UnknownMaterialListsDefinedNamesWhenNoneIsClose)
{
    const std::string text = kCamera + "[materials.a]\ntype = \"lambert\"\n[materials.b]\ntype = \"mirror\"\n"
                                       "[[objects]]\nshape = \"sphere\"\nmaterial = \"xyzzy\"\n";
    EXPECT_EQ(parseError(text).message(), "objects[0].material: unknown material 'xyzzy' (defined: a, b)");
}

TEST(SceneParserSuggestions, SwappedLettersCountAsOneEdit)
{
    // Two swaps: two edits with transpositions, four without (no suggestion then).
    EXPECT_EQ(parseError(kCamera + "hiegth = 45\n").message(), "camera: unknown key 'hiegth'; did you mean 'height'?");
    EXPECT_EQ(parseError(kCamera + "atrgte = 1\n").message(), "camera: unknown key 'atrgte'; did you mean 'target'?");
}

// A scene with one very long material name and an object that names a slightly
// different one: the did-you-mean once filled a |a| x |b| table (2 GB and 20 s
// at 16,000 characters, 12.6 GB at 40,000). Names that long get no suggestion.
SceneError longNameError(size_t length)
{
    const std::string defined(length, 'a');
    const std::string used = std::string(length - 1, 'a') + "b";
    return parseError(kCamera + "[materials." + defined +
                      "]\ntype = \"lambert\"\n[[objects]]\nshape = \"sphere\"\n"
                      "material = \"" +
                      used + "\"\ncenter = [0, 0, 0]\nradius = 1\n");
}

TEST(SceneParserSuggestions, VeryLongUnknownNameIsLocatedQuicklyWithoutSuggestion)
{
    for (const size_t length : {size_t{16000}, size_t{40000}}) {
        const auto start = std::chrono::steady_clock::now();
        const SceneError error = longNameError(length);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_EQ(error.where().line, 9);
        EXPECT_EQ(error.where().column, 12);
        EXPECT_EQ(error.message().rfind("objects[0].material: unknown material 'aaa", 0), 0u);
        EXPECT_EQ(error.message().find("did you mean"), std::string::npos);
        // Milliseconds now; the bound is loose for sanitizer builds on a busy machine.
        EXPECT_LT(seconds, 2.0) << length << " characters";
    }
}

TEST(SceneParserSuggestions, LongButPlausibleNameIsStillSuggested)
{
    const std::string name = "wall_left_" + std::string(50, 'x') + "_painted_red";
    const std::string typo = "wall_left_" + std::string(50, 'x') + "_painted_rde";
    const std::string text = kCamera + "[materials." + name +
                             "]\ntype = \"lambert\"\n[[objects]]\nshape = \"sphere\"\n"
                             "material = \"" +
                             typo + "\"\ncenter = [0, 0, 0]\nradius = 1\n";
    EXPECT_EQ(parseError(text).message(),
              "objects[0].material: unknown material '" + typo + "'; did you mean '" + name + "'?");
}

// ------------------------------------------------ inputs that crash toml++ 3.3

class SceneParserTomlTrap : public ::testing::TestWithParam<TomlTrap> {};

TEST_P(SceneParserTomlTrap, IsALocatedSyntaxError)
{
    const std::string& line = GetParam().text;
    for (const std::string& before : {std::string(), kCamera}) {
        const SceneError error = parseError(before + line + "\n");
        const int expectedLine = before.empty() ? 1 : 5;
        EXPECT_EQ(error.where().file, "scene.toml");
        EXPECT_EQ(error.where().line, expectedLine) << error.what();
        EXPECT_GE(error.where().column, 1) << error.what();
        EXPECT_LE(error.where().column, int(line.size()) + 1) << error.what();
        EXPECT_EQ(error.message().rfind("invalid TOML: ", 0), 0u) << error.what();
    }
}

INSTANTIATE_TEST_SUITE_P(TomlTraps, SceneParserTomlTrap, ::testing::ValuesIn(kTomlTraps),
                         [](const ::testing::TestParamInfo<TomlTrap>& info) { return info.param.name; });

// ---------------------------------------------------------- bad cubemap files

class SceneParserCubemap : public ::testing::Test {
protected:
    void SetUp() override
    {
        for (const char* face : {"px", "nx", "py", "ny", "pz"}) m_dir.write(std::string("sky/") + face + ".exr", "x");
    }

    SceneError errorFor(const std::string& background) const
    {
        return parseError(kCamera + background, (m_dir.path() / "scene.toml").string());
    }

    static std::string faces(const std::string& nz)
    {
        return "[background.cubemap]\npx = \"sky/px.exr\"\nnx = \"sky/nx.exr\"\npy = \"sky/py.exr\"\n"
               "ny = \"sky/ny.exr\"\npz = \"sky/pz.exr\"\n" +
               nz;
    }

    TempDir m_dir;
};

TEST_F(SceneParserCubemap, MissingFaceFile)
{
    const SceneError error = errorFor(faces("nz = \"sky/nz.exr\"\n"));
    EXPECT_NE(error.message().find("background.cubemap.nz: file '"), std::string::npos) << error.what();
    EXPECT_NE(error.message().find("nz.exr' does not exist"), std::string::npos) << error.what();
    EXPECT_EQ(error.where().line, 11);
    EXPECT_EQ(error.where().column, 6);
}

TEST_F(SceneParserCubemap, MissingFaceKey)
{
    const SceneError error = errorFor(faces(""));
    EXPECT_EQ(error.message(), "background.cubemap: missing required key 'nz'");
    EXPECT_EQ(error.where().line, 5);
    EXPECT_EQ(error.where().column, 1);
}

TEST_F(SceneParserCubemap, WrongExtension)
{
    m_dir.write("sky/nz.jpg", "x");
    const SceneError error = errorFor(faces("nz = \"sky/nz.jpg\"\n"));
    EXPECT_NE(error.message().find("background.cubemap.nz: cubemap faces must be .exr or .png files"),
              std::string::npos)
        << error.what();
    EXPECT_EQ(error.where().line, 11);
    EXPECT_EQ(error.where().column, 6);
}

TEST_F(SceneParserCubemap, FaceIsADirectory)
{
    fs::create_directories(m_dir.path() / "sky" / "nz.exr");
    const SceneError error = errorFor(faces("nz = \"sky/nz.exr\"\n"));
    EXPECT_NE(error.message().find("is not a regular file"), std::string::npos) << error.what();
    EXPECT_EQ(error.where().line, 11);
}

TEST_F(SceneParserCubemap, UnknownFaceKey)
{
    const SceneError error = errorFor(faces("nzz = \"sky/nz.exr\"\n"));
    EXPECT_EQ(error.message(), "background.cubemap: unknown key 'nzz'; did you mean 'nz'?");
    EXPECT_EQ(error.where().line, 11);
    EXPECT_EQ(error.where().column, 1);
}

} // namespace
TEST(SceneParserMaterials, RoughDielectricOfRoughnessZeroIsTheSmoothDielectric)
{
    const Scene scene = parseSceneString(kCamera + "[materials.a]\ntype = \"rough_dielectric\"\nroughness = 0\n"
                                                   "[materials.b]\ntype = \"rough_dielectric\"\n");
    ASSERT_EQ(scene.materials.size(), 2u);
    EXPECT_EQ(scene.materials[0].type, MaterialType::Dielectric); // same kind, kernel and image as `dielectric`
    EXPECT_EQ(scene.materials[1].type, MaterialType::RoughDielectric);
    EXPECT_NEAR(scene.materials[1].roughness, std::sqrt(0.1), 1e-12); // Mitsuba's default alpha = 0.1
}

TEST(SceneParserMaterials, NamedMetalsAndDefaults)
{
    const Scene scene = parseSceneString(kCamera + "[materials.gold]\ntype = \"conductor\"\nmetal = \"Au\"\n"
                                                   "[materials.perfect]\ntype = \"conductor\"\n"
                                                   "[materials.gltf]\ntype = \"pbr\"\n");
    EXPECT_NEAR(scene.materials[0].eta.r, 0.1431, 1e-9);
    EXPECT_NEAR(scene.materials[0].k.b, 1.6032, 1e-9);
    EXPECT_EQ(scene.materials[1].eta, Color(0.0)); // Mitsuba's "none": F = 1 at every angle
    EXPECT_EQ(scene.materials[1].k, Color(1.0));
    EXPECT_EQ(scene.materials[2].metallic, 1.0); // glTF's defaults
    EXPECT_EQ(scene.materials[2].roughness, 1.0);
    EXPECT_EQ(scene.materials[2].diffuse, Color(1.0));
}

} // namespace vkrt
