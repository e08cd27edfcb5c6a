// Lat-long environment maps ([background.environment]) against what this
// file computes on the CPU from the map itself:
// - the convention (Mitsuba 3's envmap: column centres, rows from pole to
//   pole, bilinear, wrapping in u) and the rotation, from camera rays that
//   see the map directly;
// - a white furnace: a convex white sphere in a constant map vanishes;
// - importance sampling: a plane lit by a sky with a small hot sun has the
//   radiance albedo / pi times the map's irradiance (integrated here), and
//   sampling the map lowers its error at equal spp.
#include "io/ExrFile.h"
#include "render/Renderer.h"
#include "render/Sky.h"
#include "support/TestSupport.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class LatLongEnvironment : public GpuTest {};

/// The map's bilinear radiance at map direction m (Mitsuba 3's envmap).
glm::dvec3 mapRadiance(const Image& map, const glm::dvec3& m)
{
    const double pi = glm::pi<double>();
    double u = std::atan2(m.x, -m.z) / (2.0 * pi);
    if (u < 0.0) u += 1.0;
    const double v = std::acos(std::clamp(m.y, -1.0, 1.0)) / pi;
    const int w = int(map.width), h = int(map.height);
    const double x = u * w - 0.5, y = v * (h - 1);
    const int i0 = ((int(std::floor(x)) % w) + w) % w, i1 = (i0 + 1) % w;
    const int j0 = std::clamp(int(std::floor(y)), 0, h - 2);
    const double tx = x - std::floor(x), ty = y - j0;
    auto texel = [&](int i, int j) {
        const float* t = map.at(uint32_t(i), uint32_t(j));
        return glm::dvec3(t[0], t[1], t[2]);
    };
    return glm::mix(glm::mix(texel(i0, j0), texel(i1, j0), tx), glm::mix(texel(i0, j0 + 1), texel(i1, j0 + 1), tx), ty);
}

/// Irradiance on a surface facing world +y: the map integrated over the
/// upper hemisphere by the midpoint rule, `sub` x `sub` points per texel.
glm::dvec3 irradianceFacingUp(const Image& map, const glm::dmat3& rotation, int sub)
{
    const double pi = glm::pi<double>();
    const int nu = int(map.width) * sub, nv = int(map.height - 1) * sub;
    glm::dvec3 sum(0.0);
    for (int b = 0; b < nv; ++b) {
        const double v = (b + 0.5) / nv, theta = pi * v;
        for (int a = 0; a < nu; ++a) {
            const double phi = 2.0 * pi * (a + 0.5) / nu;
            const glm::dvec3 m(std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta));
            const double cosine = (rotation * m).y;
            if (cosine > 0.0) sum += mapRadiance(map, m) * cosine * std::sin(theta);
        }
    }
    return sum * (2.0 * pi * pi / (double(nu) * nv));
}

std::string environmentTable(const std::string& extra)
{
    return "[background.environment]\nfile = \"map.exr\"\n" + extra;
}

TEST_F(LatLongEnvironment, CameraRaysSeeTheMapInMitsubasConventionAndRotation)
{
    const fs::path dir = freshTempDir("latlong-convention");
    Image map(8, 5);
    std::mt19937 random(7);
    std::uniform_real_distribution<float> value(0.1f, 2.0f);
    for (float& v : map.rgb) v = value(random);
    writeExr(dir / "map.exr", map, {});
    const glm::dmat3 rotation(glm::rotate(glm::dmat4(1.0), glm::radians(30.0), glm::normalize(glm::dvec3(1, 2, 3))));
    const std::string text =
        "[render]\nmax_depth = 1\n"
        "[camera]\neye = [0, 0, 0]\ntarget = [0.3, 0.2, -1]\nfov = 120\nwidth = 48\nheight = 32\n" +
        environmentTable("rotate = { axis = [1, 2, 3], angle = 30 }\n");
    const Scene scene = sceneFromText(text, (dir / "scene.toml").string());
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(1);
    const Image image = renderer.mean();
    const Camera& c = scene.camera;
    const glm::dvec3 forward = glm::normalize(c.target - c.eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, c.up)), up = glm::cross(right, forward);
    const double halfHeight = std::tan(glm::radians(c.fovY) / 2.0), halfWidth = halfHeight * c.width / c.height;
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const double ndcX = 2.0 * (x + 0.5) / c.width - 1.0, ndcY = 1.0 - 2.0 * (y + 0.5) / c.height;
            const glm::dvec3 d = glm::normalize(ndcX * halfWidth * right + ndcY * halfHeight * up + forward);
            const glm::dvec3 want = mapRadiance(map, glm::transpose(rotation) * d);
            // lavapipe's atan and acos are good to about 1e-5 radians (a
            // hundredth of this map's texel): a wrong convention is off by O(1).
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(image.at(x, y)[ch], want[ch], 1e-3 * want[ch]) << x << "," << y << " channel " << ch;
        }
    }
}

TEST_F(LatLongEnvironment, WhiteFurnaceSphereVanishesInBothIntegrators)
{
    const fs::path dir = freshTempDir("latlong-furnace");
    Image map(16, 9);
    std::fill(map.rgb.begin(), map.rgb.end(), 1.0f);
    writeExr(dir / "map.exr", map, {});
    for (const char* integrator : {"whitted", "path"}) {
        const std::string text = std::string("[render]\nintegrator = \"") + integrator +
                                 "\"\nmax_depth = 2\n"
                                 "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\nfov = 20\nwidth = 12\nheight = 12\n"
                                 "[materials.white]\ntype = \"lambert\"\nalbedo = 1\n"
                                 "[[objects]]\nshape = \"sphere\"\nmaterial = \"white\"\ncenter = [0, 0, 0]\n"
                                 "radius = 1\n" +
                                 environmentTable("scale = [0.5, 1, 2]\n");
        const Scene scene = sceneFromText(text, (dir / "scene.toml").string());
        RenderOptions options = statisticalOptions(5);
        Renderer renderer(gpu(), scene, options);
        renderer.renderFrames(256);
        const double scale[3] = {0.5, 1.0, 2.0};
        for (int ch = 0; ch < 3; ++ch) {
            // A constant map is sampled by the cosine lobe, which finds this
            // sphere's light exactly: every sample equal up to rounding, no
            // variance to divide by.
            const double mean = channelMean(renderer.mean(), ch);
            if (channelMean(renderer.varianceOfMean(), ch) < 1e-12 * scale[ch] * scale[ch]) {
                EXPECT_NEAR(mean, scale[ch], 1e-6 * scale[ch]) << integrator << " channel " << ch;
                continue;
            }
            const double z = pooledZ(renderer.mean(), renderer.varianceOfMean(), ch, scale[ch]);
            EXPECT_LT(std::abs(z), 4.0) << integrator << " channel " << ch << ": mean " << mean;
        }
    }
}

// A constant map's light samples follow the cosine lobe about the shading
// normal (RENDER_FLAG_CONSTANT_ENVIRONMENT): a Lambertian sphere filling the
// view then gets albedo x radiance from every sample, its light sample and its
// BSDF ray each half of it, so its variance is zero where light samples
// uniform over the sphere gave each pixel a variance of the mean of about
// 2e-4 at 64 spp.
TEST_F(LatLongEnvironment, AConstantMapIsSampledByTheCosineLobe)
{
    const fs::path dir = freshTempDir("latlong-constant");
    Image map(16, 9);
    for (size_t i = 0; i < map.rgb.size(); i += 3) {
        map.rgb[i] = 1.0f;
        map.rgb[i + 1] = 2.0f;
        map.rgb[i + 2] = 0.5f;
    }
    writeExr(dir / "map.exr", map, {});
    const std::string text = "[render]\nintegrator = \"path\"\nmax_depth = 1\n"
                             "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\nfov = 20\nwidth = 8\nheight = 8\n"
                             "[materials.grey]\ntype = \"lambert\"\nalbedo = 0.5\n"
                             "[[objects]]\nshape = \"sphere\"\nmaterial = \"grey\"\ncenter = [0, 0, 0]\n"
                             "radius = 1\n" +
                             environmentTable("");
    const Scene scene = sceneFromText(text, (dir / "scene.toml").string());
    Renderer renderer(gpu(), scene, statisticalOptions(11));
    renderer.renderFrames(64);
    const Image mean = renderer.mean(), variance = renderer.varianceOfMean();
    const double want[3] = {0.5, 1.0, 0.25};
    for (uint32_t y = 0; y < mean.height; ++y)
        for (uint32_t x = 0; x < mean.width; ++x)
            for (int ch = 0; ch < 3; ++ch) {
                EXPECT_NEAR(mean.at(x, y)[ch], want[ch], 1e-5) << x << "," << y << " channel " << ch;
                EXPECT_LT(variance.at(x, y)[ch], 1e-10) << x << "," << y << " channel " << ch;
            }
}

/// A 128 x 65 sky with a sun 4 degrees across carrying most of the light.
Image sunnySky()
{
    SkyParameters sky;
    sky.sunElevationDegrees = 50.0;
    sky.sunAzimuthDegrees = 30.0;
    sky.sunAngularRadiusDegrees = 2.0;
    sky.sunRadiance = 2000.0;
    return renderSkyLatLong(sky, 128);
}

std::string sunnyPlaneScene(const std::string& integrator)
{
    return "[render]\nintegrator = \"" + integrator +
           "\"\nmax_depth = 1\n"
           "[camera]\neye = [0, 3, 0]\ntarget = [0, 0, 0]\nup = [0, 0, -1]\nfov = 20\nwidth = 16\nheight = 16\n"
           "[materials.white]\ntype = \"lambert\"\nalbedo = 0.5\n"
           "[[objects]]\nshape = \"plane\"\nmaterial = \"white\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n" +
           environmentTable("rotate = { axis = [0, 1, 0], angle = 70 }\n");
}

TEST_F(LatLongEnvironment, ImportanceSamplingOfASmallSunIsUnbiasedAndLowersTheError)
{
    const fs::path dir = freshTempDir("latlong-sun");
    const Image map = sunnySky();
    writeExr(dir / "map.exr", map, {});
    const glm::dmat3 rotation(glm::rotate(glm::dmat4(1.0), glm::radians(70.0), glm::dvec3(0, 1, 0)));
    const double expected = 0.5 / glm::pi<double>() * irradianceFacingUp(map, rotation, 8).x;
    for (const char* integrator : {"whitted", "path"}) {
        const Scene scene = sceneFromText(sunnyPlaneScene(integrator), (dir / "scene.toml").string());
        auto render = [&](bool sampled, bool variance, uint32_t spp) {
            RenderOptions options = statisticalOptions(9);
            options.variance = variance;
            if (!sampled) options.extraDefines.push_back({"VKRT_TEST_NO_ENVIRONMENT_SAMPLING", "1"});
            Renderer renderer(gpu(), scene, options);
            renderer.renderFrames(spp);
            return renderer;
        };
        const Renderer sampled = render(true, true, 512);
        const double z = pooledZ(sampled.mean(), sampled.varianceOfMean(), 0, expected);
        reportStat(std::string("sun_plane_pooled_z_") + integrator, z);
        EXPECT_LT(std::abs(z), 4.0) << integrator << ": mean " << channelMean(sampled.mean(), 0) << ", expected "
                                    << expected;
        // Equal spp, the same pixels: squared error against the closed form.
        // (The Whitted integrator at max_depth 1 traces no continuation: without
        // sampling the map it has no light at all, so only the path integrator
        // measures what sampling gains.)
        if (std::string(integrator) != "path") continue;
        auto mse = [&](const Image& image) {
            double sum = 0.0;
            for (size_t i = 0; i < image.pixelCount(); ++i) sum += std::pow(image.rgb[i * 3] - expected, 2);
            return sum / double(image.pixelCount());
        };
        const double withSampling = mse(render(true, false, 16).mean());
        const double bsdfOnly = mse(render(false, false, 16).mean());
        reportStat(std::string("sun_plane_mse_ratio_bsdf_over_sampled_") + integrator, bsdfOnly / withSampling);
        EXPECT_GT(bsdfOnly, 10.0 * withSampling) << integrator;
    }
}

} // namespace
} // namespace vkrt::test
