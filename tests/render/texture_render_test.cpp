// Textured materials on the GPU, each checked against an answer worked out
// here from the documented conventions (docs/scene-format.md, "Textures" and
// "Texture coordinates"), not from the texture code:
// - a Lambert surface under a uniform white sky, one bounce, shows exactly
//   its albedo, so a textured albedo shows the texel: the image appears
//   upright on planes, box faces, spheres and meshes;
// - a distant one-texel checker is filtered to its linear mean (mip-mapping
//   by ray cones), while a near one keeps its contrast;
// - a constant normal map tilts a plane's shading normal in its tangent
//   frame, which changes a point light's Lambert term to a closed form.
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureImage.h"
#include "texture/TextureTestFiles.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

namespace vkrt::test {
namespace {

class TextureRender : public GpuTest {};

constexpr uint32_t kSide = 33; // odd: the centre pixel looks along the view axis

Image renderCentres(const Scene& scene, uint32_t frames = 1)
{
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(frames);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
    return renderer.mean();
}

// ------------------------------------------------- orientation on every shape

/// 16 x 16 sRGB texels in four uniform quadrants (rows top to bottom as in the file).
struct Quadrants {
    static constexpr uint8_t topLeft[3] = {255, 0, 0};
    static constexpr uint8_t topRight[3] = {0, 255, 0};
    static constexpr uint8_t bottomLeft[3] = {0, 0, 255};
    static constexpr uint8_t bottomRight[3] = {128, 128, 128};
};

std::filesystem::path writeQuadrantTexture(const std::filesystem::path& dir)
{
    std::vector<uint8_t> samples;
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = 0; x < 16; ++x) {
            const uint8_t* c = y < 8 ? (x < 8 ? Quadrants::topLeft : Quadrants::topRight)
                                     : (x < 8 ? Quadrants::bottomLeft : Quadrants::bottomRight);
            samples.insert(samples.end(), c, c + 3);
        }
    return write8BitPng(dir / "quadrants.png", 16, 16, 3, samples);
}

/// A camera on +z looking at the origin whose view at z = 0 is exactly [-0.5, 0.5]^2.
std::string frontCamera()
{
    const double fov = 2.0 * std::atan(0.5 / 3.0) * 180.0 / 3.14159265358979323846;
    return "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nfov = " +
           std::to_string(fov) + "\nwidth = " + std::to_string(kSide) + "\nheight = " + std::to_string(kSide) +
           "\n[background]\ncolor = [1, 1, 1]\n"
           "[materials.textured]\ntype = \"lambert\"\nalbedo = { texture = \"quadrants.png\", wrap = \"clamp\" }\n";
}

void expectTexel(const Image& image, uint32_t x, uint32_t y, const uint8_t (&srgb)[3], const std::string& what)
{
    for (int c = 0; c < 3; ++c) {
        const double expected = srgbToLinear(srgb[c] / 255.0);
        EXPECT_NEAR(image.at(x, y)[c], expected, 2e-4)
            << what << " got " << image.at(x, y)[0] << " " << image.at(x, y)[1] << " " << image.at(x, y)[2]
            << ": pixel (" << x << ", " << y << ") channel " << c;
    }
}

/// The pixels at the quadrants' centres show the quadrants of the image, upright.
void expectUpright(const Image& image, const std::string& what)
{
    const uint32_t low = kSide / 4, high = kSide - 1 - kSide / 4;
    expectTexel(image, low, low, Quadrants::topLeft, what + ", top left");
    expectTexel(image, high, low, Quadrants::topRight, what + ", top right");
    expectTexel(image, low, high, Quadrants::bottomLeft, what + ", bottom left");
    expectTexel(image, high, high, Quadrants::bottomRight, what + ", bottom right");
}

TEST_F(TextureRender, ImageAppearsUprightOnPlanesBoxesSpheresAndMeshes)
{
    const auto dir = freshTempDir("texture-upright");
    writeQuadrantTexture(dir);
    {
        std::ofstream(dir / "quad.obj") << "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
                                           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    }
    const std::string scenePath = (dir / "scene.toml").string();
    // A plane facing +z: u along +x, v along +y, one unit per scene unit from its point.
    const std::string plane = "[[objects]]\nshape = \"plane\"\npoint = [-0.5, -0.5, 0]\nnormal = [0, 0, 1]\n"
                              "material = \"textured\"\n";
    // A box's +z face spans [0, 1]^2 over the face.
    const std::string box = "[[objects]]\nshape = \"box\"\nmin = [-0.5, -0.5, -1]\nmax = [0.5, 0.5, 0]\n"
                            "material = \"textured\"\n";
    // A mesh quad with the OBJ's uvs (0, 0) at its bottom-left corner.
    const std::string mesh = "[[objects]]\nshape = \"mesh\"\nfile = \"quad.obj\"\nmaterial = \"textured\"\n";
    // A sphere seen from +z: u = 0.5 at +z, growing towards +x; v = 0.5 at the
    // equator, 1 at the top. Small enough that the quadrants' centres in the
    // image see uvs well inside the texture's quadrants.
    const std::string sphere = "[[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.4\n"
                               "material = \"textured\"\n";
    expectUpright(renderCentres(parseSceneString(frontCamera() + plane, scenePath)), "plane");
    expectUpright(renderCentres(parseSceneString(frontCamera() + box, scenePath)), "box");
    expectUpright(renderCentres(parseSceneString(frontCamera() + mesh, scenePath)), "mesh");
    expectUpright(renderCentres(parseSceneString(frontCamera() + sphere, scenePath)), "sphere");
}

// ----------------------------------------------------------- mip-mapping

/// A black-and-white checker of side x side texels in squares of `block` texels.
std::filesystem::path writeChecker(const std::filesystem::path& dir, uint32_t side, uint32_t block = 1)
{
    std::vector<uint8_t> samples;
    for (uint32_t y = 0; y < side; ++y)
        for (uint32_t x = 0; x < side; ++x) samples.push_back((x / block + y / block) % 2 ? 255 : 0);
    return write8BitPng(dir / "checker.png", side, side, 1, samples);
}

/// A floor under a white sky seen from 1 unit above it, with a one-texel checker at uv scale `scale`.
std::string checkerFloorText(double scale)
{
    return "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [0, 1, 0]\n"
           "target = [0, 0.2, -4]\nfov = 40\nwidth = " +
           std::to_string(kSide) + "\nheight = " + std::to_string(kSide) +
           "\n[background]\ncolor = [1, 1, 1]\n[materials.floor]\ntype = \"lambert\"\n"
           "albedo = { texture = \"checker.png\", scale = " +
           std::to_string(scale) +
           " }\n[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n"
           "material = \"floor\"\n";
}

Image renderCheckerFloor(const std::filesystem::path& dir, double scale)
{
    return renderCentres(parseSceneString(checkerFloorText(scale), (dir / "scene.toml").string()));
}

TEST_F(TextureRender, DistantCheckerIsFilteredToItsLinearMeanNearOneKeepsItsContrast)
{
    const auto dir = freshTempDir("texture-mips");
    writeChecker(dir, 64);
    // Minified: every pixel's footprint covers hundreds of texels. Point
    // samples of the checker would read 0 or 1; its mip levels average to
    // 0.5 in linear light (an average of the sRGB codes would give 0.21).
    const Image far = renderCheckerFloor(dir, 512.0);
    // Magnified: each texel spans several pixels, so level 0 is used and the
    // pixels read black, white and bilinear blends of the two.
    const Image near = renderCheckerFloor(dir, 0.05);
    double farMin = 1e9, farMax = -1e9, nearMin = 1e9, nearMax = -1e9, farSum = 0;
    size_t floorPixels = 0;
    for (uint32_t y = 0; y < kSide; ++y)
        for (uint32_t x = 0; x < kSide; ++x) {
            if (far.at(x, y)[0] == 1.0f && far.at(x, y)[2] == 1.0f && y < kSide / 3) continue; // the sky
            const double f = far.at(x, y)[0], n = near.at(x, y)[0];
            farMin = std::min(farMin, f), farMax = std::max(farMax, f), farSum += f;
            nearMin = std::min(nearMin, n), nearMax = std::max(nearMax, n);
            ++floorPixels;
        }
    ASSERT_GT(floorPixels, kSide * kSide / 2) << "the floor should fill most of the image";
    EXPECT_NEAR(farSum / double(floorPixels), 0.5, 0.01);
    EXPECT_GT(farMin, 0.45) << "a distant pixel was not filtered (aliasing)";
    EXPECT_LT(farMax, 0.55) << "a distant pixel was not filtered (aliasing)";
    EXPECT_LT(nearMin, 0.05) << "the near checker lost its black texels: blurred although magnified";
    EXPECT_GT(nearMax, 0.95) << "the near checker lost its white texels: blurred although magnified";
}

// Every jittered sample of a pixel filters textures over the same footprint,
// so the samples are identically distributed: a render of few samples has the
// expectation of one of many, and its variance estimate covers all of its
// error. (A footprint narrowing with the sample's index, as once here, made a
// 64-sample image the texture filtered wider than a 1024-sample one: an error
// no variance estimate sees, and most of the error per sample on textured
// models; docs/performance.md, round four.) A checker of one to seven texels
// per pixel in squares of eight: beside an edge, a wider footprint reaches
// across it, so where the footprint depends on the sample's index, few and
// many samples differ there while a pixel's samples barely vary.
TEST_F(TextureRender, FewJitteredSamplesAverageToTheImageOfManyWithinTheirVariance)
{
    const auto dir = freshTempDir("texture-iid");
    writeChecker(dir, 64, 8);
    const Scene scene = parseSceneString(checkerFloorText(0.5), (dir / "scene.toml").string());
    auto render = [&](uint32_t frames, uint32_t seed, Image& varianceOfMean) {
        Renderer renderer(gpu(), scene, statisticalOptions(seed));
        renderer.renderFrames(frames);
        varianceOfMean = renderer.varianceOfMean();
        return renderer.mean();
    };
    constexpr uint32_t kFew = 64, kMany = 1024;
    Image fewVariance, manyVariance;
    const Image few = render(kFew, 1, fewVariance);
    const Image many = render(kMany, 2, manyVariance);
    double sumSquaredZ = 0;
    size_t pixels = 0;
    for (uint32_t y = 0; y < kSide; ++y)
        for (uint32_t x = 0; x < kSide; ++x) {
            // One sample's variance from the many samples (64 samples of a
            // pixel that an edge barely crosses often estimate it as 0).
            // The floor: the float sums' rounding (a pixel whose samples
            // all but agree still differs by ~1e-5 between the two means).
            const double sampleVariance = double(manyVariance.at(x, y)[0]) * kMany;
            const double variance = sampleVariance / kFew + sampleVariance / kMany + 1e-10;
            const double difference = double(few.at(x, y)[0]) - double(many.at(x, y)[0]);
            if (sampleVariance == 0.0 && difference == 0.0) continue; // the sky, or inside a square: exact
            sumSquaredZ += difference * difference / variance;
            ++pixels;
        }
    ASSERT_GT(pixels, kSide * kSide / 8) << "too few pixels vary to test anything";
    // With equal expectations E[(few - many)^2] is the variance above, so the
    // mean of z^2 is 1; over n pixels it spreads by about sqrt(2 / n) (more
    // for the skewed pixels an edge barely crosses). Five spreads.
    const double meanSquaredZ = sumSquaredZ / double(pixels);
    RecordProperty("mean_squared_z", std::to_string(meanSquaredZ));
    EXPECT_LT(meanSquaredZ, 1.0 + 5.0 * std::sqrt(2.0 / double(pixels)))
        << "64 samples do not average to 1024 samples' image within their variance: the samples' texture "
           "footprints differ";
}

// ------------------------------------------------------------ filters

// A 2 x 2 checker (black and white texels) filling the view, magnified about
// 16 times: with `filter = "nearest"` every pixel shows a texel exactly, 0 or
// 1, the edges between them sharp; bilinear (the default) blends the texels
// between their centres.
TEST_F(TextureRender, NearestMagnificationShowsTheTexelsBilinearBlendsThem)
{
    const auto dir = freshTempDir("texture-nearest");
    write8BitPng(dir / "checker.png", 2, 2, 1, {0, 255, 255, 0});
    auto render = [&](const std::string& filter) {
        std::string text = frontCamera();
        const std::string quadrants = "texture = \"quadrants.png\"";
        text.replace(text.find(quadrants), quadrants.size(), "texture = \"checker.png\"" + filter);
        text +=
            "[[objects]]\nshape = \"plane\"\npoint = [-0.5, -0.5, 0]\nnormal = [0, 0, 1]\nmaterial = \"textured\"\n";
        return renderCentres(parseSceneString(text, (dir / "scene.toml").string()));
    };
    const Image nearest = render(", filter = \"nearest\""), linear = render("");
    size_t blended = 0, off = 0;
    for (uint32_t y = 0; y < kSide; ++y)
        for (uint32_t x = 0; x < kSide; ++x) {
            // The pixel's centre in texels: the texel it lies in is black where x and y are on the same side.
            const bool left = x < kSide / 2, top = y < kSide / 2;
            if (x == kSide / 2 || y == kSide / 2) continue; // the centre row and column look at the edge itself
            const float expected = left == top ? 0.0f : 1.0f;
            for (int c = 0; c < 3; ++c) off += std::abs(nearest.at(x, y)[c] - expected) > 1e-5f;
            const float l = linear.at(x, y)[0];
            blended += l > 0.01f && l < 0.99f;
        }
    EXPECT_EQ(off, 0u) << "nearest: every pixel is its texel, 0 or 1 (up to float rounding)";
    EXPECT_GT(blended, kSide * kSide / 2) << "bilinear blends between the texel centres";
}

// ------------------------------------------------------------ normal maps

/// A 4 x 4 linear normal map of one tangent-space normal, given as 8-bit codes.
void writeConstantNormalMap(const std::filesystem::path& file, const std::array<uint8_t, 3>& code)
{
    std::vector<uint8_t> samples;
    for (int i = 0; i < 16; ++i) samples.insert(samples.end(), code.begin(), code.end());
    write8BitPng(file, 4, 4, 3, samples);
}

/// The tangent-space normal a texel of `code` stands for (rgb = (n + 1) / 2), normalised.
glm::dvec3 decodeNormal(const std::array<uint8_t, 3>& code)
{
    return glm::normalize(glm::dvec3(code[0], code[1], code[2]) * (2.0 / 255.0) - 1.0);
}

/// Looking straight down at the floor's origin; albedo 0.5; a point light of intensity 10 at `light`.
std::string normalMapScene(const std::string& integrator, const glm::dvec3& light, const std::string& floor)
{
    auto vec = [](const glm::dvec3& v) {
        return "[" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + "]";
    };
    return "[render]\nintegrator = \"" + integrator +
           "\"\nmax_depth = 1\n[camera]\neye = [0, 3, 0]\n"
           "target = [0, 0, 0]\nup = [0, 0, -1]\nfov = 20\nwidth = " +
           std::to_string(kSide) + "\nheight = " + std::to_string(kSide) +
           "\n[materials.bumpy]\ntype = \"lambert\"\nalbedo = 0.5\n"
           "normal_map = { texture = \"normals.png\" }\n[[lights]]\ntype = \"point\"\nposition = " +
           vec(light) + "\nintensity = [10, 10, 10]\n" + floor;
}

/// Radiance at the floor's origin: albedo / pi * I * cos(mapped normal, light) / d^2.
double expectedRadiance(const glm::dvec3& mappedNormal, const glm::dvec3& light)
{
    const double cosine = std::max(0.0, glm::dot(mappedNormal, glm::normalize(light)));
    return 0.5 / 3.14159265358979323846 * 10.0 * cosine / glm::dot(light, light);
}

TEST_F(TextureRender, ConstantNormalMapTiltsTheShadingNormalInTheTangentFrame)
{
    const auto dir = freshTempDir("texture-normal-map");
    {
        // Corners CCW seen from above (normal +y), uv: u along +x, v along -z.
        std::ofstream(dir / "floor.obj") << "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\n"
                                            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    }
    // The floor's tangent frame by the documented conventions: tangent +x
    // (increasing u), bitangent -z (increasing v), normal +y, for the plane
    // (tangent = cross(+y, n), else +x; bitangent = cross(n, tangent)), the
    // box's top face and the mesh's uvs alike.
    const glm::dvec3 tangent(1, 0, 0), bitangent(0, 0, -1), normal(0, 1, 0);
    const std::vector<std::pair<std::string, std::string>> floors = {
        {"plane", "[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nmaterial = \"bumpy\"\n"},
        {"box", "[[objects]]\nshape = \"box\"\nmin = [-1, -1, -1]\nmax = [1, 0, 1]\nmaterial = \"bumpy\"\n"},
        {"mesh", "[[objects]]\nshape = \"mesh\"\nfile = \"floor.obj\"\nmaterial = \"bumpy\"\n"},
    };
    // Tilted 30 degrees towards +tangent, then towards +bitangent; each lit
    // from the side it tilts to, where the wrong sign would give a far smaller cosine.
    const std::vector<std::pair<std::array<uint8_t, 3>, glm::dvec3>> cases = {
        {{191, 128, 238}, glm::dvec3(2, 2, 0)},
        {{128, 191, 238}, glm::dvec3(0, 2, -2)},
    };
    for (const auto& [code, light] : cases) {
        writeConstantNormalMap(dir / "normals.png", code);
        const glm::dvec3 local = decodeNormal(code);
        const glm::dvec3 mapped = glm::normalize(local.x * tangent + local.y * bitangent + local.z * normal);
        const double expected = expectedRadiance(mapped, light);
        const double unmapped = expectedRadiance(normal, light);
        ASSERT_GT(expected, 1.2 * unmapped) << "the case does not tell a tilted normal from a flat one";
        for (const auto& [name, floor] : floors)
            for (const std::string integrator : {"path", "whitted"}) {
                const Scene scene =
                    parseSceneString(normalMapScene(integrator, light, floor), (dir / "scene.toml").string());
                const Image image = renderCentres(scene);
                EXPECT_NEAR(image.at(kSide / 2, kSide / 2)[0], expected, 2e-3 * expected)
                    << name << ", " << integrator << ", normal map code " << int(code[0]) << " " << int(code[1]) << " "
                    << int(code[2]) << " (flat normal would give " << unmapped << ")";
            }
    }
}

// ------------------------------------------- pbr anisotropy and coat normals

/// The floor of the normal-map tests (tangent +x, bitangent -z, normal +y),
/// seen from straight above, under material `surface` and a point light of
/// intensity 10 at `light`.
std::string floorScene(const glm::dvec3& light, const std::string& surface, const std::string& shape)
{
    auto vec = [](const glm::dvec3& v) {
        return "[" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + "]";
    };
    const std::string floor =
        shape == "plane"
            ? "[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nmaterial = \"surface\"\n"
            : "[[objects]]\nshape = \"mesh\"\nfile = \"floor.obj\"\nmaterial = \"surface\"\n";
    return "[render]\nintegrator = \"path\"\nmax_depth = 1\n[camera]\neye = [0, 3, 0]\ntarget = [0, 0, 0]\n"
           "up = [0, 0, -1]\nfov = 20\nwidth = " +
           std::to_string(kSide) + "\nheight = " + std::to_string(kSide) + "\n[materials.surface]\ntype = \"pbr\"\n" +
           surface + "[[lights]]\ntype = \"point\"\nposition = " + vec(light) + "\nintensity = [10, 10, 10]\n" + floor;
}

/// Smith GGX with the height-correlated G, D G / (4 N.V N.L), for directions
/// given in a frame whose x axis has alpha ax and y axis alpha ay (written from
/// KHR_materials_anisotropy's D_GGX_anisotropic and V_GGX_anisotropic).
double anisotropicGgx(const glm::dvec3& v, const glm::dvec3& l, double ax, double ay)
{
    const glm::dvec3 h = glm::normalize(v + l);
    const double a2 = ax * ay;
    const glm::dvec3 f(ay * h.x, ax * h.y, a2 * h.z);
    const double w2 = a2 / glm::dot(f, f);
    const double d = a2 * w2 * w2 / 3.14159265358979323846;
    const double visibility = 0.5 / (l.z * glm::length(glm::dvec3(ax * v.x, ay * v.y, v.z)) +
                                     v.z * glm::length(glm::dvec3(ax * l.x, ay * l.y, l.z)));
    return d * visibility;
}

/// Directions in the floor's frame turned by `angle` about its normal: x along
/// cos(angle) tangent + sin(angle) bitangent.
glm::dvec3 inTurnedFloorFrame(const glm::dvec3& world, double angle)
{
    const glm::dvec3 t(1, 0, 0), b(0, 0, -1), n(0, 1, 0);
    const glm::dvec3 x = std::cos(angle) * t + std::sin(angle) * b, y = glm::cross(n, x);
    return {glm::dot(world, x), glm::dot(world, y), glm::dot(world, n)};
}

TEST_F(TextureRender, PbrAnisotropyStretchesTheHighlightAlongItsDirectionInTheTangentFrame)
{
    const auto dir = freshTempDir("texture-anisotropy");
    std::ofstream(dir / "floor.obj") << "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\n"
                                        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    // A direction texture along the bitangent: rg = ((0, 1) + 1) / 2, strength (b) 1.
    writeConstantNormalMap(dir / "directions.png", {128, 255, 255});
    // A white metal (Fresnel 1 at every angle), roughness 0.3, strength 0.8:
    // alpha 0.09 across, mix(0.09, 1, 0.64) = 0.6724 along the direction.
    const double alpha = 0.09, stretched = alpha + (1.0 - alpha) * 0.64;
    const std::string metal = "base_color = 1\nmetallic = 1\nroughness = 0.3\nanisotropy = 0.8\n";
    const glm::dvec3 wo(0, 1, 0);
    struct Case {
        std::string name, surface;
        double angle; // of the stretched axis from the tangent, towards the bitangent
    };
    const std::vector<Case> cases = {
        {"rotation 0", metal, 0.0},
        {"rotation 90", metal + "anisotropy_rotation = 90\n", std::numbers::pi / 2},
        {"rotation 30", metal + "anisotropy_rotation = 30\n", std::numbers::pi / 6},
        {"texture along the bitangent", metal + "anisotropy_texture = { texture = \"directions.png\" }\n",
         std::numbers::pi / 2},
        {"texture turned by -90",
         metal + "anisotropy_rotation = -90\nanisotropy_texture = { texture = \"directions.png\" }\n", 0.0},
    };
    // Lights off to the side along the tangent and along the bitangent (-z): the
    // highlight reaches the farther one where the lobe is stretched towards it.
    for (const glm::dvec3 light : {glm::dvec3(1.2, 2, 0), glm::dvec3(0, 2, -1.2)})
        for (const Case& c : cases)
            for (const std::string shape : {"plane", "mesh"}) {
                const glm::dvec3 wi = glm::normalize(light);
                const double f =
                    anisotropicGgx(inTurnedFloorFrame(wo, c.angle), inTurnedFloorFrame(wi, c.angle), stretched, alpha);
                const double expected = f * 10.0 * wi.y / glm::dot(light, light);
                const double across =
                    anisotropicGgx(inTurnedFloorFrame(wo, c.angle + std::numbers::pi / 2),
                                   inTurnedFloorFrame(wi, c.angle + std::numbers::pi / 2), stretched, alpha) *
                    10.0 * wi.y / glm::dot(light, light);
                ASSERT_GT(std::abs(expected - across), 0.2 * expected) << "the case does not tell the two axes apart";
                const Scene scene =
                    parseSceneString(floorScene(light, c.surface, shape), (dir / "scene.toml").string());
                const Image image = renderCentres(scene);
                EXPECT_NEAR(image.at(kSide / 2, kSide / 2)[0], expected, 3e-3 * expected)
                    << c.name << ", " << shape << ", light (" << light.x << ", " << light.y << ", " << light.z
                    << "); stretched across it instead: " << across;
            }
}

TEST_F(TextureRender, TheCoatTakesItsOwnNormalMapNotTheBases)
{
    const auto dir = freshTempDir("texture-coat-normal");
    writeConstantNormalMap(dir / "normals.png", {191, 128, 238}); // tilted 30 degrees towards +tangent
    // Only the coat reflects: a black base with no dielectric specular (KHR_materials_specular 0).
    const std::string coat = "base_color = 0\nmetallic = 0\nspecular = 0\nclearcoat = 1\nclearcoat_roughness = 0.4\n";
    const glm::dvec3 light(2, 2, 0), wi = glm::normalize(light), wo(0, 1, 0);
    const glm::dvec3 tilted = glm::normalize(decodeNormal({191, 128, 238}).x * glm::dvec3(1, 0, 0) +
                                             decodeNormal({191, 128, 238}).z * glm::dvec3(0, 1, 0));
    // The coat about normal nc: clearcoat Fc(nc.wo) S(nc) (nc.wi) I / d^2, with
    // Fc = 0.04 + 0.96 (1 - nc.wo)^5 and S the GGX of alpha 0.16 about nc.
    auto coatRadiance = [&](const glm::dvec3& nc) {
        const glm::dvec3 t = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), nc)), b = glm::cross(nc, t);
        auto local = [&](const glm::dvec3& w) { return glm::dvec3(glm::dot(w, t), glm::dot(w, b), glm::dot(w, nc)); };
        const double cosO = glm::dot(nc, wo);
        const double fresnel = 0.04 + 0.96 * std::pow(1.0 - cosO, 5.0);
        return fresnel * anisotropicGgx(local(wo), local(wi), 0.16, 0.16) * glm::dot(nc, wi) * 10.0 /
               glm::dot(light, light);
    };
    const double flat = coatRadiance(glm::dvec3(0, 1, 0)), mapped = coatRadiance(tilted);
    ASSERT_GT(mapped, 1.5 * flat) << "the case does not tell a tilted coat from a flat one";
    const std::vector<std::pair<std::string, double>> cases = {
        {coat + "clearcoat_normal_map = { texture = \"normals.png\" }\n", mapped},
        {coat + "normal_map = { texture = \"normals.png\" }\n", flat},
    };
    for (const auto& [surface, expected] : cases) {
        const Scene scene = parseSceneString(floorScene(light, surface, "plane"), (dir / "scene.toml").string());
        const Image image = renderCentres(scene);
        EXPECT_NEAR(image.at(kSide / 2, kSide / 2)[0], expected, 3e-3 * expected)
            << surface << "(flat coat " << flat << ", tilted coat " << mapped << ")";
    }
}

// ------------------------------------------------------------ kernel variants

// The textured variant and the all-features kernel compute the same image,
// bit for bit (Whitted, whose samples do not depend on the optional features).
TEST_F(TextureRender, TexturedSceneRendersAsWithTheUberKernel)
{
    const auto dir = freshTempDir("texture-uber");
    writeChecker(dir, 8);
    writeConstantNormalMap(dir / "normals.png", {191, 128, 238});
    const std::string text = R"([render]
integrator = "whitted"
max_depth = 3
[camera]
eye = [0, 1.5, 4]
target = [0, 0.5, 0]
fov = 40
width = 40
height = 30
[materials.floor]
type = "lambert"
albedo = { texture = "checker.png", scale = 2 }
[materials.ball]
type = "phong"
diffuse = { texture = "checker.png", wrap = "mirror" }
specular = 0.3
normal_map = { texture = "normals.png" }
[materials.metal]
type = "conductor"
metal = "Cu"
roughness = { texture = "checker.png", linear = true }
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
[[objects]]
shape = "sphere"
center = [-0.7, 0.6, 0]
radius = 0.6
material = "ball"
[[objects]]
shape = "box"
min = [0.3, 0, -0.5]
max = [1.3, 1, 0.5]
material = "metal"
[[lights]]
type = "point"
position = [2, 4, 3]
intensity = [30, 30, 30]
)";
    const Scene scene = parseSceneString(text, (dir / "scene.toml").string());
    RenderOptions specializedOptions = pixelCentreOptions(), uberOptions = pixelCentreOptions();
    uberOptions.uber = true;
    Renderer specialized(gpu(), scene, specializedOptions), uber(gpu(), scene, uberOptions);
    specialized.renderFrames(2);
    uber.renderFrames(2);
    const Image a = specialized.mean(), b = uber.mean();
    size_t differing = 0, lit = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        differing += a.rgb[i] != b.rgb[i];
        lit += a.rgb[i] > 0.0f;
    }
    EXPECT_EQ(differing, 0u);
    EXPECT_GT(lit, a.rgb.size() / 2) << "most of the image should be lit";
}

// ------------------------------------------------- texels in several buffers

/// Words a texel of `format` takes.
uint32_t wordsPerTexel(uint32_t format) { return format == gpu::TEXTURE_FORMAT_RGBA16F ? 2u : 1u; }

/// Levels of `format` (among `records`) whose words straddle a boundary of chunks of 2^shift words.
int straddlingLevels(const std::vector<gpu::TextureRecord>& records, uint32_t shift, uint32_t format)
{
    int count = 0;
    for (const gpu::TextureRecord& r : records) {
        if (r.format != format) continue;
        for (uint32_t level = 0; level < r.levels; ++level) {
            const uint64_t words =
                uint64_t(std::max(1u, r.width >> level)) * std::max(1u, r.height >> level) * wordsPerTexel(r.format);
            const uint64_t first = r.levelOffset[level], last = first + words - 1;
            count += (first >> shift) != (last >> shift);
        }
    }
    return count;
}

// Texels split into many small buffers (RenderOptions::maxTextureChunkBytes,
// as a scene beyond maxStorageBufferRange is) render exactly as in one: the
// same words read, the same arithmetic. Levels of 8-bit sRGB, 8-bit linear
// and half-float textures straddle the chunks' boundaries.
TEST_F(TextureRender, TexelsInSmallChunksRenderBitForBitAsInOneBuffer)
{
    const auto dir = freshTempDir("texture-chunks");
    writeChecker(dir, 64);
    writeQuadrantTexture(dir);
    std::vector<uint16_t> wide;
    for (uint32_t y = 0; y < 10; ++y)
        for (uint32_t x = 0; x < 12; ++x)
            wide.insert(wide.end(), {uint16_t(x * 5000), uint16_t(y * 6000), uint16_t(30000 + x * y * 300), 65535});
    writePng(dir / "wide.png", 12, 10, 16, 6, wide); // 16-bit: half floats
    std::vector<uint8_t> rough;
    for (uint32_t i = 0; i < 7 * 5; ++i) rough.push_back(uint8_t(40 + 5 * i));
    write8BitPng(dir / "rough.png", 7, 5, 1, rough);
    const std::string text = R"([render]
integrator = "path"
max_depth = 2
[camera]
eye = [0, 1.5, 4]
target = [0, 0.5, 0]
fov = 40
width = 40
height = 30
[background]
color = [0.8, 0.9, 1.0]
[materials.floor]
type = "lambert"
albedo = { texture = "checker.png", scale = 3 }
[materials.ball]
type = "lambert"
albedo = { texture = "quadrants.png", wrap = "mirror" }
[materials.wide]
type = "lambert"
albedo = { texture = "wide.png", scale = [2, 1] }
[materials.metal]
type = "conductor"
metal = "Au"
roughness = { texture = "rough.png", linear = true }
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
[[objects]]
shape = "sphere"
center = [-0.8, 0.6, 0]
radius = 0.6
material = "ball"
[[objects]]
shape = "box"
min = [0.2, 0, -0.5]
max = [1.2, 1, 0.5]
material = "wide"
[[objects]]
shape = "sphere"
center = [0.2, 0.3, 1.2]
radius = 0.3
material = "metal"
[[lights]]
type = "point"
position = [2, 4, 3]
intensity = [30, 30, 30]
)";
    const Scene scene = parseSceneString(text, (dir / "scene.toml").string());
    RenderOptions oneOptions = pixelCentreOptions(), splitOptions = pixelCentreOptions();
    splitOptions.maxTextureChunkBytes = 1024; // 256 words a buffer
    Renderer one(gpu(), scene, oneOptions), split(gpu(), scene, splitOptions);
    EXPECT_EQ(one.variant().textureChunks, 1u);
    const TextureBuffers& textures = split.meshData().textures;
    ASSERT_EQ(split.variant().textureChunks, textures.chunking.count);
    EXPECT_EQ(textures.chunking.shift, 8u);
    EXPECT_EQ(textures.chunking.count, (textures.texels.size() + 255) / 256);
    EXPECT_GT(textures.chunking.count, 20u);
    for (uint32_t format :
         {gpu::TEXTURE_FORMAT_RGBA8_SRGB, gpu::TEXTURE_FORMAT_RGBA8_UNORM, gpu::TEXTURE_FORMAT_RGBA16F})
        EXPECT_GT(straddlingLevels(textures.records, 8, format), 0) << "format " << format;
    one.renderFrames(2);
    split.renderFrames(2);
    const Image a = one.mean(), b = split.mean();
    size_t differing = 0;
    std::vector<float> values;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        differing += a.rgb[i] != b.rgb[i];
        values.push_back(a.rgb[i]);
    }
    EXPECT_EQ(differing, 0u);
    std::sort(values.begin(), values.end());
    EXPECT_GT(std::unique(values.begin(), values.end()) - values.begin(), 500) << "the textures should show";
}

// --------------------------------------------------------- glTF file materials

/// Two quads side by side in the plane z = 0 facing +z (left x in [-1, 0],
/// right x in [0, 1], y in [-0.5, 0.5]), each a primitive of its own material.
std::string twoQuadGltf(const std::string& materials)
{
    std::string buffer;
    for (float x0 : {-1.0f, 0.0f}) {
        const float x1 = x0 + 1.0f;
        for (float v : {x0, -0.5f, 0.f, x1, -0.5f, 0.f, x1, 0.5f, 0.f, x0, -0.5f, 0.f, x1, 0.5f, 0.f, x0, 0.5f, 0.f})
            put(buffer, v);
    }
    return R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0},
                             {"attributes": {"POSITION": 1}, "material": 1}]}],
  "materials": )" +
           materials + R"(,
  "buffers": [{"uri": ")" +
           dataUri("application/octet-stream", buffer) + R"(", "byteLength": 144}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 144}],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 6, "type": "VEC3", "min": [-1, -0.5, 0], "max": [0, 0.5, 0]},
    {"bufferView": 0, "byteOffset": 72, "componentType": 5126, "count": 6, "type": "VEC3", "min": [0, -0.5, 0], "max": [1, 0.5, 0]}]})";
}

// Each triangle takes its own file material: two emissive glTF materials on
// one mesh show their own emission on their own halves, seen directly (black
// surroundings, black base colour, so nothing else adds to it).
TEST_F(TextureRender, GltfMaterialsApplyPerTriangleWithTheirEmission)
{
    const auto dir = freshTempDir("texture-gltf-emission");
    std::ofstream(dir / "quads.gltf") << twoQuadGltf(
        R"([{"name": "Red", "emissiveFactor": [1, 0, 0], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}},
            {"name": "Green", "emissiveFactor": [0, 0.5, 0], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}}])");
    const std::string text = "[render]\nintegrator = \"path\"\nmax_depth = 2\n[camera]\neye = [0, 0, 3]\n"
                             "target = [0, 0, 0]\nfov = 30\nwidth = " +
                             std::to_string(kSide) + "\nheight = " + std::to_string(kSide) +
                             "\n[[objects]]\nshape = \"mesh\"\nfile = \"quads.gltf\"\nmaterial = \"file\"\n";
    const Scene scene = parseSceneString(text, (dir / "scene.toml").string());
    const Image image = renderCentres(scene);
    const float* left = image.at(kSide / 2 - 4, kSide / 2);
    const float* right = image.at(kSide / 2 + 4, kSide / 2);
    EXPECT_NEAR(left[0], 1.0, 1e-5);
    EXPECT_NEAR(left[1], 0.0, 1e-5);
    EXPECT_NEAR(right[0], 0.0, 1e-5);
    EXPECT_NEAR(right[1], 0.5, 1e-5);
    EXPECT_NEAR(image.at(0, 0)[0] + image.at(0, 0)[1], 0.0, 1e-6) << "outside the quads the image is black";
}

} // namespace
} // namespace vkrt::test
