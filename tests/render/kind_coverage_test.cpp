// Every shape kind of the registry (shared/Kinds.h), and every light kind
// with area, is seen by the camera both in a scene without meshes (the
// kernel's per-kind loops) and in one with a mesh (the top-level BVH over the
// bounded kinds, and loops over the unbounded ones). A kind that one of the
// registry-generated sites misses (lib/scene.glsl's record dispatch, the
// host's buildTopLevel) vanishes from one of the two images, and a kind
// added to the registry without a fixture here fails the test.
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <filesystem>
#include <map>
#include <string>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class KindCoverage : public GpuTest {};

// A unit square facing +z at the origin, for the mesh kind and the decoy.
constexpr const char* kQuadObj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n";

/// One record of the kind across the centre of the view (the camera looks
/// at the origin from +z), lit by the point light at the eye.
const std::map<std::string, std::string>& shapeFixtures()
{
    static const std::map<std::string, std::string> fixtures{
        {"sphere", "shape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.5\n"},
        {"box", "shape = \"box\"\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.5, 0.5]\n"},
        {"triangle", "shape = \"triangle\"\nvertices = [[-1, -1, 0], [1, -1, 0], [0, 1, 0]]\n"},
        {"plane", "shape = \"plane\"\npoint = [0, 0, -1]\nnormal = [0, 0, 1]\n"},
        {"mesh", "shape = \"mesh\"\nfile = \"quad.obj\"\nscale = 0.5\n"},
    };
    return fixtures;
}

/// Light kinds rays can hit (bounded = 1): one facing the camera at the centre.
const std::map<std::string, std::string>& lightFixtures()
{
    static const std::map<std::string, std::string> fixtures{
        {"triangle", "type = \"triangle\"\nvertices = [[-1, -1, 0], [1, -1, 0], [0, 1, 0]]\nradiance = 2\n"},
    };
    return fixtures;
}

std::string sceneText(const std::string& extra, bool decoyMesh)
{
    std::string text = "[render]\nintegrator = \"whitted\"\nmax_depth = 2\n"
                       "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 30\nwidth = 9\nheight = 9\n"
                       "[materials.white]\ntype = \"lambert\"\nalbedo = 0.8\n"
                       "[[lights]]\ntype = \"point\"\nposition = [0, 0, 5]\nintensity = 50\n" +
                       extra;
    // Far outside the view: it only makes the scene one with meshes.
    if (decoyMesh)
        text += "[[objects]]\nshape = \"mesh\"\nfile = \"quad.obj\"\ntranslate = [40, 40, -40]\nmaterial = \"white\"\n";
    return text;
}

/// The radiance at the centre pixel of the scene.
double centreRadiance(const fs::path& dir, const std::string& text)
{
    const Scene scene = sceneFromText(text, (dir / "scene.toml").string());
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(1);
    const Image image = renderer.mean();
    const size_t centre = (size_t(image.height / 2) * image.width + image.width / 2) * 3;
    return image.rgb[centre] + image.rgb[centre + 1] + image.rgb[centre + 2];
}

void expectSeenWithAndWithoutMesh(const fs::path& dir, const std::string& table, const std::string& what)
{
    EXPECT_EQ(centreRadiance(dir, sceneText("", true)), 0.0) << "the decoy mesh is in view";
    for (bool decoy : {false, true}) {
        const double seen = centreRadiance(dir, sceneText(table, decoy));
        EXPECT_GT(seen, 0.0) << what << " is missing from a scene " << (decoy ? "with" : "without") << " a mesh";
    }
}

TEST_F(KindCoverage, EveryShapeKindIsSeenWithAndWithoutAMesh)
{
    const fs::path dir = freshTempDir("kind-coverage");
    writeText(dir / "quad.obj", kQuadObj);
    int tested = 0;
#define VKRT_TEST_SHAPE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded)                   \
    if (const auto fixture = shapeFixtures().find(#name); fixture == shapeFixtures().end()) {              \
        ADD_FAILURE() << "shape kind " #name " has no fixture here";                                       \
    } else {                                                                                               \
        expectSeenWithAndWithoutMesh(dir, "[[objects]]\nmaterial = \"white\"\n" + fixture->second, #name); \
        ++tested;                                                                                          \
    }
    VKRT_SHAPE_KINDS(VKRT_TEST_SHAPE)
#undef VKRT_TEST_SHAPE
    EXPECT_EQ(tested, int(kShapeKindCount));
}

/// Every light kind without area, shining on a white plane at the centre of
/// the view from in front of it (the point light at the eye is left out).
const std::map<std::string, std::string>& unboundedLightFixtures()
{
    static const std::map<std::string, std::string> fixtures{
        {"point", "type = \"point\"\nposition = [0, 0, 3]\nintensity = 5\n"},
        {"directional", "type = \"directional\"\ndirection = [0, -1, -1]\nirradiance = 2\nangle = 1\n"},
        {"spot", "type = \"spot\"\nposition = [0, 0, 3]\ndirection = [0, 0, -1]\nintensity = 5\n"},
    };
    return fixtures;
}

/// The centre radiance of a white plane through the origin facing +z lit only
/// by `light`, with either integrator, with and without the decoy mesh.
void expectLightsThePlane(const fs::path& dir, const std::string& light, const std::string& what)
{
    for (const char* integrator : {"whitted", "path"}) {
        for (bool decoy : {false, true}) {
            std::string text = std::string("[render]\nintegrator = \"") + integrator +
                               "\"\nmax_depth = 2\n"
                               "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 30\nwidth = 9\nheight = 9\n"
                               "[materials.white]\ntype = \"lambert\"\nalbedo = 0.8\n"
                               "[[objects]]\nshape = \"plane\"\nmaterial = \"white\"\npoint = [0, 0, 0]\n"
                               "normal = [0, 0, 1]\n[[lights]]\n" +
                               light;
            if (decoy)
                text += "[[objects]]\nshape = \"mesh\"\nfile = \"quad.obj\"\ntranslate = [40, 40, -40]\n"
                        "material = \"white\"\n";
            EXPECT_GT(centreRadiance(dir, text), 0.0)
                << what << " lights nothing with " << integrator << (decoy ? " and a mesh" : "");
        }
    }
}

TEST_F(KindCoverage, EveryLightKindWithoutAreaLightsASurface)
{
    const fs::path dir = freshTempDir("kind-coverage-unbounded");
    writeText(dir / "quad.obj", kQuadObj);
    int tested = 0;
#define VKRT_TEST_UNBOUNDED_LIGHT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded)   \
    if (bounded == 0) {                                                                             \
        if (const auto f = unboundedLightFixtures().find(#name); f == unboundedLightFixtures().end()) { \
            ADD_FAILURE() << "light kind " #name " has no fixture here";                            \
        } else {                                                                                    \
            expectLightsThePlane(dir, f->second, "light kind " #name);                               \
            ++tested;                                                                               \
        }                                                                                           \
    }
    VKRT_LIGHT_KINDS(VKRT_TEST_UNBOUNDED_LIGHT)
#undef VKRT_TEST_UNBOUNDED_LIGHT
    EXPECT_GT(tested, 0);
}

TEST_F(KindCoverage, EveryLightKindWithAreaIsSeenWithAndWithoutAMesh)
{
    const fs::path dir = freshTempDir("kind-coverage-lights");
    writeText(dir / "quad.obj", kQuadObj);
    int tested = 0;
#define VKRT_TEST_LIGHT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded)              \
    if (bounded != 0) {                                                                               \
        if (const auto fixture = lightFixtures().find(#name); fixture == lightFixtures().end()) {     \
            ADD_FAILURE() << "light kind " #name " has no fixture here";                              \
        } else {                                                                                      \
            expectSeenWithAndWithoutMesh(dir, "[[lights]]\n" + fixture->second, "light kind " #name); \
            ++tested;                                                                                 \
        }                                                                                             \
    }
    VKRT_LIGHT_KINDS(VKRT_TEST_LIGHT)
#undef VKRT_TEST_LIGHT
    EXPECT_GT(tested, 0);
}

} // namespace
} // namespace vkrt::test
