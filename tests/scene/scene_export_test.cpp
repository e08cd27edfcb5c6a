// The scene export (scene/SceneExport.h, docs/scene-json.md): every field
// equals the parsed Scene's value after a round trip through the text,
// defaults are filled in, paths are absolute, and every registry kind appears.
#include "scene/SceneExport.h"

#include "scene/SceneParser.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

/// Every shape, light and material kind, textures, a mesh with a matrix and a cubemap.
const char* kEveryKind = R"(
[render]
integrator = "path"
max_depth = 7
[camera]
eye = [0.1, 1.3333333333333333, 6.02e-3]
target = [0, 1, 0]
up = [0, 1, 0.2]
fov = 37.7
width = 33
height = 17
[materials.clay]
type = "lambert"
albedo = { texture = "grey.png", scale = [4, 2], wrap = "clamp" }
[materials.shiny]
type = "phong"
diffuse = [0.1, 0.2, 0.3]
specular = 0.4
shininess = 64.5
[materials.chrome]
type = "mirror"
reflectance = 0.95
fresnel = "schlick"
ior = 2.5
[materials.brushed]
type = "glossy"
exponent = 200
[materials.glass]
type = "dielectric"
absorption = [0.05, 0.02, 0]
[materials.gold]
type = "conductor"
metal = "Au"
roughness = { texture = "grey.png", channel = "g", linear = true }
[materials.frost]
type = "rough_dielectric"
ior = 1.33
fresnel = "exact"
[materials.toy]
type = "plastic"
diffuse = [0.7, 0.1, 0.1]
roughness = 0.2
[materials.wood]
type = "pbr"
base_color = [0.5, 0.4, 0.3]
metallic = 0.25
normal_map = { texture = "grey.png", strength = 0.5, filter = "nearest" }
[[objects]]
shape = "sphere"
material = "glass"
center = [0, 1, 0]
radius = 0.30000000000000004
[[objects]]
shape = "box"
material = "shiny"
min = [1.5, 0, -1]
max = [2.5, 1, 0]
[[objects]]
shape = "triangle"
material = "chrome"
vertices = [[-3, 0, -2], [-1, 0, -2], [-2, 2, -2]]
[[objects]]
shape = "plane"
material = "brushed"
point = [0, 0, 0]
normal = [0, 2, 0]
[[objects]]
shape = "mesh"
material = "clay"
file = "sub/../quad.obj"
matrix = [[2, 0, 0, 5], [0, 1, 0, 0.1], [0, 0, 1, -3], [0, 0, 0, 1]]
normals = "smooth"
emission = [1, 2, 3]
two_sided = true
[[objects]]
shape = "sphere"
material = "gold"
center = [1, 1, 1]
radius = 1
[[objects]]
shape = "sphere"
material = "frost"
center = [2, 1, 1]
radius = 1
[[objects]]
shape = "sphere"
material = "toy"
center = [3, 1, 1]
radius = 1
[[objects]]
shape = "mesh"
material = "wood"
file = "quad.obj"
scale = 0.5
[[lights]]
type = "point"
position = [3, 5, 3]
intensity = [40, 41, 42]
[[lights]]
type = "triangle"
vertices = [[-1, 4, -1], [1, 4, -1], [0, 4, 1]]
radiance = 20
two_sided = true
[[lights]]
type = "directional"
direction = [0, -2, 0]
irradiance = [1, 2, 3]
angle = 0.5
[[lights]]
type = "spot"
position = [0, 3, 0]
direction = [0, 0, -3]
intensity = 7
inner_cone_angle = 10
[background.cubemap]
px = "grey.png"
nx = "grey.png"
py = "grey.png"
ny = "grey.png"
pz = "grey.png"
nz = "grey.png"
)";

const char* kQuadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";

class SceneExport : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = textureTestDir();
        write8BitPng(m_dir / "grey.png", 2, 2, 3, std::vector<uint8_t>(12, 128));
        fs::create_directories(m_dir / "sub");
        std::ofstream(m_dir / "quad.obj") << kQuadObj;
    }

    Scene parse(const std::string& text) const { return parseSceneString(text, (m_dir / "scene.toml").string()); }

    /// The export as another program reads it: the text, parsed again.
    static Json exported(const Scene& scene) { return Json::parse(exportSceneText(scene)); }

    fs::path m_dir;
};

/// Bit-exact comparison, so that -0.0 and 0.0 or a last-digit rounding would show.
void expectSameDouble(const Json& value, double expected, const std::string& what)
{
    ASSERT_TRUE(value.is_number()) << what << ": " << value.dump();
    const double got = value.get<double>();
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << what << ": " << got << " != " << expected;
}

void expectSameVector(const Json& value, const glm::dvec3& expected, const std::string& what)
{
    ASSERT_TRUE(value.is_array() && value.size() == 3) << what << ": " << value.dump();
    for (int i = 0; i < 3; ++i) expectSameDouble(value[size_t(i)], expected[i], what + "[" + std::to_string(i) + "]");
}

void expectSamePoints(const Json& value, const std::array<glm::dvec3, 3>& expected, const std::string& what)
{
    ASSERT_EQ(value.size(), 3u) << what;
    for (size_t i = 0; i < 3; ++i) expectSameVector(value[i], expected[i], what + "[" + std::to_string(i) + "]");
}

TEST_F(SceneExport, HeaderCameraAndRenderEqualTheScene)
{
    const Scene scene = parse(kEveryKind);
    const Json j = exported(scene);
    EXPECT_EQ(j["format"], "vkrt-scene");
    EXPECT_EQ(j["version"], kSceneJsonVersion);
    EXPECT_EQ(j["scene"]["path"], fs::absolute(m_dir / "scene.toml").lexically_normal().string());
    EXPECT_EQ(j["scene"]["hash"].get<std::string>().rfind("fnv1a64:", 0), 0u);
    EXPECT_EQ(j["render"]["integrator"], "path");
    EXPECT_EQ(j["render"]["max_depth"], 7);
    const Json& c = j["camera"];
    expectSameVector(c["eye"], scene.camera.eye, "eye");
    expectSameVector(c["target"], scene.camera.target, "target");
    expectSameVector(c["up"], scene.camera.up, "up");
    expectSameDouble(c["fov"], scene.camera.fovY, "fov");
    EXPECT_EQ(c["width"], 33);
    EXPECT_EQ(c["height"], 17);
}

TEST_F(SceneExport, DefaultsAreFilledIn)
{
    const Json j = exported(parse("[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n"
                                  "[materials.m]\ntype = \"lambert\"\n"
                                  "[materials.g]\ntype = \"dielectric\"\n"));
    EXPECT_EQ(j["render"]["integrator"], "whitted");
    EXPECT_EQ(j["render"]["max_depth"], 5);
    EXPECT_EQ(j["camera"]["up"], Json::parse("[0.0, 1.0, 0.0]"));
    EXPECT_EQ(j["camera"]["width"], 640);
    EXPECT_EQ(j["camera"]["height"], 480);
    EXPECT_EQ(j["materials"][0]["albedo"], Json::parse("[0.8, 0.8, 0.8]"));
    EXPECT_TRUE(j["materials"][0]["textures"].empty());
    // Whitted picks Schlick for a dielectric without `fresnel`; the export says so and that it was not given.
    EXPECT_EQ(j["materials"][1]["fresnel"], "schlick");
    EXPECT_EQ(j["materials"][1]["fresnel_explicit"], false);
    EXPECT_EQ(j["materials"][1]["ior"], 1.5);
    EXPECT_EQ(j["background"]["color"], Json::parse("[0.0, 0.0, 0.0]"));
    EXPECT_TRUE(j["background"]["cubemap"].is_null());
    for (const auto& [kind, records] : j["shapes"].items()) EXPECT_TRUE(records.empty()) << kind;
}

TEST_F(SceneExport, MaterialsHaveEveryParameterOfTheirKind)
{
    const Scene scene = parse(kEveryKind);
    const Json j = exported(scene);
    ASSERT_EQ(j["materials"].size(), scene.materials.size());
    const auto byName = [&](const std::string& name) {
        for (const Json& m : j["materials"])
            if (m["name"] == name) return m;
        ADD_FAILURE() << "no material " << name;
        return Json();
    };
    const auto material = [&](const std::string& name) {
        for (const Material& m : scene.materials)
            if (m.name == name) return m;
        return Material{};
    };
    const Json shiny = byName("shiny");
    EXPECT_EQ(shiny["type"], "phong");
    expectSameVector(shiny["diffuse"], material("shiny").diffuse, "shiny.diffuse");
    expectSameVector(shiny["specular"], material("shiny").specular, "shiny.specular");
    expectSameDouble(shiny["shininess"], material("shiny").exponent, "shiny.shininess");

    const Json chrome = byName("chrome");
    EXPECT_EQ(chrome["fresnel"], "schlick");
    EXPECT_EQ(chrome["fresnel_explicit"], true);
    expectSameDouble(chrome["ior"], 2.5, "chrome.ior");
    expectSameVector(chrome["reflectance"], glm::dvec3(0.95), "chrome.reflectance");
    EXPECT_EQ(byName("brushed")["fresnel"], "none");
    expectSameDouble(byName("brushed")["exponent"], 200.0, "brushed.exponent");

    const Json glass = byName("glass");
    expectSameVector(glass["absorption"], material("glass").absorption, "glass.absorption");
    EXPECT_EQ(glass["fresnel"], "exact"); // the path integrator's choice

    const Json gold = byName("gold");
    expectSameVector(gold["eta"], material("gold").eta, "gold.eta");
    expectSameVector(gold["k"], material("gold").k, "gold.k");
    expectSameVector(gold["tint"], glm::dvec3(1.0), "gold.tint");
    expectSameDouble(gold["anisotropy"], 0.0, "gold.anisotropy");
    const Json& roughness = gold["textures"]["roughness"];
    EXPECT_EQ(roughness["channel"], "g");
    EXPECT_EQ(roughness["file"], (m_dir / "grey.png").string());
    EXPECT_EQ(roughness["record"], material("gold").texture(TextureSlot::Roughness)->record);
    EXPECT_EQ(j["textures"][roughness["record"].get<size_t>()]["encoding"], "rgba8_linear");

    const Json clay = byName("clay");
    const Json& albedo = clay["textures"]["albedo"];
    EXPECT_EQ(albedo["scale"], Json::parse("[4.0, 2.0]"));
    EXPECT_EQ(albedo["channel"], "r");
    const Json& record = j["textures"][albedo["record"].get<size_t>()];
    EXPECT_EQ(record["wrap"], Json::parse(R"(["clamp", "clamp"])"));
    EXPECT_EQ(record["filter"], Json::parse(R"({"mag": "linear", "min": "linear", "mip": "linear"})"));
    EXPECT_EQ(record["encoding"], "rgba8_srgb");
    EXPECT_EQ(record["width"], 2);

    expectSameDouble(byName("frost")["roughness"], material("frost").roughness, "frost.roughness");
    expectSameDouble(byName("frost")["ior"], 1.33, "frost.ior");
    expectSameDouble(byName("toy")["roughness"], 0.2, "toy.roughness");
    expectSameDouble(byName("toy")["ior"], material("toy").ior, "toy.ior");
    const Json wood = byName("wood");
    expectSameDouble(wood["metallic"], 0.25, "wood.metallic");
    expectSameDouble(wood["roughness"], 1.0, "wood.roughness");
    expectSameVector(wood["emission"], glm::dvec3(0.0), "wood.emission");
    EXPECT_EQ(wood["textures"]["normal_map"]["strength"], 0.5);
    EXPECT_EQ(j["textures"][wood["textures"]["normal_map"]["record"].get<size_t>()]["filter"],
              Json::parse(R"({"mag": "nearest", "min": "nearest", "mip": "nearest"})"));
    EXPECT_NE(wood["where"].get<std::string>().find("scene.toml:"), std::string::npos);
}

TEST_F(SceneExport, ShapesAndLightsEqualTheScene)
{
    const Scene scene = parse(kEveryKind);
    const Json j = exported(scene);
    const Json& spheres = j["shapes"]["sphere"];
    ASSERT_EQ(spheres.size(), scene.spheres.size());
    for (size_t i = 0; i < spheres.size(); ++i) {
        expectSameVector(spheres[i]["center"], scene.spheres[i].center, "center");
        expectSameDouble(spheres[i]["radius"], scene.spheres[i].radius, "radius");
        EXPECT_EQ(spheres[i]["material"], scene.spheres[i].material);
    }
    expectSameVector(j["shapes"]["box"][0]["min"], scene.boxes[0].min, "box.min");
    expectSameVector(j["shapes"]["box"][0]["max"], scene.boxes[0].max, "box.max");
    expectSamePoints(j["shapes"]["triangle"][0]["vertices"], scene.triangles[0].vertices, "triangle");
    expectSameVector(j["shapes"]["plane"][0]["normal"], glm::dvec3(0, 1, 0), "plane.normal"); // unit
    expectSameVector(j["shapes"]["plane"][0]["point"], scene.planes[0].point, "plane.point");
    expectSameVector(j["lights"]["point"][0]["position"], scene.pointLights[0].position, "light.position");
    expectSameVector(j["lights"]["point"][0]["intensity"], scene.pointLights[0].intensity, "light.intensity");
    expectSamePoints(j["lights"]["triangle"][0]["vertices"], scene.triangleLights[0].vertices, "light.vertices");
    expectSameVector(j["lights"]["triangle"][0]["radiance"], glm::dvec3(20.0), "light.radiance");
    EXPECT_EQ(j["lights"]["triangle"][0]["two_sided"], true);
    const Json& sun = j["lights"]["directional"][0];
    expectSameVector(sun["direction"], glm::dvec3(0, -1, 0), "sun.direction"); // unit
    expectSameVector(sun["irradiance"], glm::dvec3(1, 2, 3), "sun.irradiance");
    EXPECT_EQ(sun["angle"], 0.5);
    const Json& spot = j["lights"]["spot"][0];
    expectSameVector(spot["direction"], glm::dvec3(0, 0, -1), "spot.direction");
    expectSameVector(spot["intensity"], glm::dvec3(7), "spot.intensity");
    EXPECT_EQ(spot["inner_cone_angle"], 10.0);
    EXPECT_EQ(spot["outer_cone_angle"], 45.0); // glTF's default
}

TEST_F(SceneExport, ThinLensAndTheFocusDistanceDefault)
{
    const Json pinhole = exported(parse(kEveryKind))["camera"];
    EXPECT_EQ(pinhole["aperture_radius"], 0.0);
    const std::string lens = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, -1]\nfov = 30\naperture_radius = 0.25\n";
    const Json defaulted = exported(parse(lens))["camera"];
    EXPECT_EQ(defaulted["aperture_radius"], 0.25);
    EXPECT_EQ(defaulted["focus_distance"], 4.0); // the distance to the target
    EXPECT_EQ(exported(parse(lens + "focus_distance = 2.5\n"))["camera"]["focus_distance"], 2.5);
}

TEST_F(SceneExport, LatLongEnvironmentHasItsFileScaleAndRotation)
{
    std::ofstream(m_dir / "sky.exr") << "the parser checks only that it is a file";
    const Json e = exported(parse("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = 30\n"
                                  "[background.environment]\nfile = \"sky.exr\"\nscale = [1, 2, 3]\n"
                                  "rotate = { axis = [0, 1, 0], angle = 90 }\n"))["background"]["environment"];
    EXPECT_EQ(e["file"], (m_dir / "sky.exr").string());
    expectSameVector(e["scale"], glm::dvec3(1, 2, 3), "scale");
    // 90 degrees about +y: the map's +x becomes the world's -z (column 0, row by row).
    EXPECT_NEAR(e["matrix"][2][0].get<double>(), -1.0, 1e-15);
    EXPECT_NEAR(e["matrix"][0][2].get<double>(), 1.0, 1e-15);
    EXPECT_NEAR(e["matrix"][1][1].get<double>(), 1.0, 1e-15);
}

TEST_F(SceneExport, MeshesHaveTheirResolvedFileMatrixAndGeometry)
{
    const Scene scene = parse(kEveryKind);
    const Json j = exported(scene);
    const Json& meshes = j["shapes"]["mesh"];
    ASSERT_EQ(meshes.size(), 2u);
    const Json& m = meshes[0];
    EXPECT_EQ(m["file"], (m_dir / "quad.obj").string()); // absolute, `sub/..` gone
    EXPECT_TRUE(fs::path(m["file"].get<std::string>()).is_absolute());
    EXPECT_EQ(m["normals"], "smooth");
    EXPECT_EQ(meshes[1]["normals"], "file");
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            expectSameDouble(m["matrix"][size_t(r)][size_t(c)], scene.meshes[0].objectToWorld[c][r], "matrix");
    EXPECT_EQ(m["matrix"][0][3], 5.0); // row by row: column 3 is the translation
    expectSameDouble(meshes[1]["matrix"][0][0], 0.5, "scale");
    expectSameVector(m["emission"], glm::dvec3(1, 2, 3), "emission");
    EXPECT_EQ(m["two_sided"], true);
    EXPECT_EQ(m["file_materials"], Json::array());
    EXPECT_EQ(m["geometry"]["triangles"], 2);
    EXPECT_EQ(m["geometry"]["vertices"], 4);
    EXPECT_EQ(m["geometry"]["has_uvs"], true);
    EXPECT_EQ(m["geometry"]["has_normals"], true);          // smooth normals computed
    EXPECT_EQ(meshes[1]["geometry"]["has_normals"], false); // the file has none
    expectSameVector(m["world_bounds"]["min"], glm::dvec3(5, 0.1, -3), "world_bounds.min");
    expectSameVector(m["world_bounds"]["max"], glm::dvec3(7, 1.1, -3), "world_bounds.max");
    expectSameVector(m["geometry"]["bounds"]["max"], glm::dvec3(1, 1, 0), "bounds.max");
}

TEST_F(SceneExport, PathsAreAbsolute)
{
    const fs::path previous = fs::current_path();
    fs::current_path(m_dir);
    std::ofstream("scene.toml") << kEveryKind;
    const Json j = exported(parseSceneFile("scene.toml"));
    fs::current_path(previous);
    EXPECT_EQ(j["scene"]["path"], (m_dir / "scene.toml").string());
    for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"})
        EXPECT_EQ(j["background"]["cubemap"][face], (m_dir / "grey.png").string()) << face;
    EXPECT_EQ(j["shapes"]["mesh"][0]["file"], (m_dir / "quad.obj").string());
    for (const Json& t : j["textures"]) EXPECT_EQ(t["file"], (m_dir / "grey.png").string());
}

TEST_F(SceneExport, EveryRegistryKindAppears)
{
    const Scene scene = parse(kEveryKind);
    const Json j = exported(scene);
    for (ShapeKind kind : kAllShapeKinds) {
        const std::string name(kindName(kind));
        ASSERT_TRUE(j["shapes"].contains(name)) << name;
        EXPECT_EQ(j["shapes"][name].size(), scene.count(kind)) << name;
        EXPECT_GT(j["shapes"][name].size(), 0u) << name << ": the test scene should have one";
    }
    EXPECT_EQ(j["shapes"].size(), kShapeKindCount);
    for (LightKind kind : kAllLightKinds) {
        const std::string name(kindName(kind));
        ASSERT_TRUE(j["lights"].contains(name)) << name;
        EXPECT_EQ(j["lights"][name].size(), scene.count(kind)) << name;
        EXPECT_GT(j["lights"][name].size(), 0u) << name;
    }
    EXPECT_EQ(j["lights"].size(), kLightKindCount);
    for (MaterialType type : kAllMaterialTypes) {
        bool found = false;
        for (const Json& m : j["materials"]) found = found || m["type"] == kindName(type);
        EXPECT_TRUE(found) << kindName(type);
    }
}

TEST_F(SceneExport, DoublesRoundTripThroughTheText)
{
    std::mt19937_64 random(27);
    std::string text = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n"
                       "[materials.m]\ntype = \"lambert\"\n";
    std::vector<double> radii = {0.1 + 0.2,         1.0 / 3.0, 1e-300, 4.9406564584124654e-324, 1.7976931348623157e308,
                                 123456789.12345679};
    for (int i = 0; i < 200; ++i)
        radii.push_back(std::ldexp(double(random() >> 11) / 9007199254740992.0 + 0.5, int(random() % 200) - 100));
    for (double r : radii) {
        char number[40];
        std::snprintf(number, sizeof number, "%.17g", r);
        text += std::string("[[objects]]\nshape = \"sphere\"\nmaterial = \"m\"\ncenter = [0, 0, 0]\nradius = ") +
                number + "\n";
    }
    const Scene scene = parse(text);
    const Json j = exported(scene);
    ASSERT_EQ(j["shapes"]["sphere"].size(), radii.size());
    for (size_t i = 0; i < radii.size(); ++i)
        expectSameDouble(j["shapes"]["sphere"][i]["radius"], scene.spheres[i].radius, "radius " + std::to_string(i));
}

} // namespace
} // namespace vkrt::test
