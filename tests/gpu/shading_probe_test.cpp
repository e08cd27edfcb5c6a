// The shading library (shaders/lib) run on the test GPU through the probe
// kernels in tests/gpu/kernels and checked against double-precision references
// computed here: Fresnel reflectance (fresnel.glsl), refraction through
// sampleDielectric (bsdf.glsl) and the uniform triangle sampler
// (sampling.glsl, driven by the render kernels' random.glsl), with statistical
// tests that are shown to reject a deliberately wrong sampler.
#include "support/ChiSquare.h"
#include "support/ProbeKernel.h"
#include "support/TestSupport.h"

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

// ---------------------------------------------------------------------------
// Helpers

/// |actual - expected| <= rel * |expected| + abs, with both values in the message.
::testing::AssertionResult closeTo(double actual, double expected, double rel, double abs = 0.0)
{
    double err = std::abs(actual - expected);
    if (std::isfinite(actual) && err <= rel * std::abs(expected) + abs) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "actual " << actual << " expected " << expected << " (error " << err
                                         << ", allowed " << rel * std::abs(expected) + abs << ")";
}

double square(double x) { return x * x; }

/// Records a measured statistic in the test's XML properties and prints it.
// ---------------------------------------------------------------------------
// Fresnel references (double precision)

/// Schlick R0 = ((1 - n) / (1 + n))^2.
double schlickR0Ref(double ior) { return square((1.0 - ior) / (1.0 + ior)); }

/// Schlick's approximation R0 + (1 - R0)(1 - cos)^5.
double schlickRef(double cosTheta, double r0) { return r0 + (1.0 - r0) * std::pow(1.0 - cosTheta, 5.0); }

/// Sine squared of the transmitted angle by Snell's law, n_i sin(i) = n_t sin(t).
double sin2TransmittedRef(double cosI, double ni, double nt) { return square(ni / nt) * (1.0 - cosI * cosI); }

/// Textbook unpolarized Fresnel reflectance for light going from index ni to nt:
/// rs = (ni cos i - nt cos t) / (ni cos i + nt cos t),
/// rp = (nt cos i - ni cos t) / (nt cos i + ni cos t), R = (rs^2 + rp^2) / 2.
double fresnelExactRef(double cosI, double ni, double nt)
{
    double sin2T = sin2TransmittedRef(cosI, ni, nt);
    if (sin2T >= 1.0) return 1.0;
    double cosT = std::sqrt(1.0 - sin2T);
    double rs = (ni * cosI - nt * cosT) / (ni * cosI + nt * cosT);
    double rp = (nt * cosI - ni * cosT) / (nt * cosI + ni * cosT);
    return 0.5 * (rs * rs + rp * rp);
}

struct FresnelCase {
    float cosI;
    float eta; ///< n_incident / n_transmitted
    float ior;
};

/// What tests/gpu/kernels/fresnel_probe.comp writes for one case.
struct FresnelResult {
    float schlick;            ///< fresnelSchlick(cosI, schlickR0(ior))
    float exact;              ///< fresnelExact(cosI, eta)
    float schlickDielectric;  ///< fresnelSchlickDielectric(cosI, eta, ior)
    float reflectanceExact;   ///< dielectricReflectance(FRESNEL_EXACT, cosI, eta, ior)
    float reflectanceSchlick; ///< dielectricReflectance(FRESNEL_SCHLICK, cosI, eta, ior)
    float r0;                 ///< schlickR0(ior)
};

std::vector<FresnelResult> runFresnel(const std::vector<FresnelCase>& cases)
{
    std::vector<float> input;
    for (const FresnelCase& c : cases) input.insert(input.end(), {c.cosI, c.eta, c.ior});
    std::vector<float> out = runProbe("fresnel_probe", input, 6 * cases.size(), uint32_t(cases.size()));
    std::vector<FresnelResult> results(cases.size());
    for (size_t i = 0; i < cases.size(); ++i) {
        const float* r = &out[6 * i];
        results[i] = {r[0], r[1], r[2], r[3], r[4], r[5]};
    }
    return results;
}

std::string describe(const FresnelCase& c)
{
    return "cosI=" + std::to_string(c.cosI) + " eta=" + std::to_string(c.eta) + " ior=" + std::to_string(c.ior);
}

constexpr std::array<float, 5> kIors = {1.0f, 1.33f, 1.5f, 2.4f, 10.0f};

/// cos = i / n for i = 0..n: both ends included.
std::vector<float> cosineGrid(int n)
{
    std::vector<float> cosines;
    for (int i = 0; i <= n; ++i) cosines.push_back(float(double(i) / n));
    return cosines;
}

class FresnelProbe : public GpuTest {};

// ---------------------------------------------------------------------------
// 1. Schlick

TEST_F(FresnelProbe, SchlickMatchesClosedFormAndR0)
{
    std::vector<FresnelCase> cases;
    for (float ior : kIors)
        for (float c : cosineGrid(1000)) cases.push_back({c, 1.0f / ior, ior});
    std::vector<FresnelResult> results = runFresnel(cases);

    double worst = 0.0;
    for (size_t i = 0; i < cases.size(); ++i) {
        const FresnelCase& c = cases[i];
        double expected = schlickRef(c.cosI, schlickR0Ref(c.ior));
        EXPECT_TRUE(closeTo(results[i].schlick, expected, 1e-5, 1e-30)) << describe(c);
        // Entering the denser medium, the dielectric variant uses the incident cosine.
        EXPECT_TRUE(closeTo(results[i].schlickDielectric, expected, 1e-5, 1e-30)) << describe(c);
        EXPECT_EQ(results[i].reflectanceSchlick, results[i].schlickDielectric) << describe(c);
        // schlickR0 = ((1 - n) / (1 + n))^2, exactly 0 for n = 1.
        EXPECT_TRUE(closeTo(results[i].r0, schlickR0Ref(c.ior), 1e-6)) << describe(c);
        if (expected > 0.0) worst = std::max(worst, std::abs(results[i].schlick - expected) / expected);
        // At normal incidence Schlick is R0 itself.
        if (c.cosI == 1.0f) {
            EXPECT_EQ(results[i].schlick, results[i].r0) << describe(c);
        }
        // At grazing incidence everything is reflected.
        if (c.cosI == 0.0f) {
            EXPECT_TRUE(closeTo(results[i].schlick, 1.0, 1e-6)) << describe(c);
        }
    }
    reportStat("SchlickMaxRelativeError", worst);
}

// Leaving the denser medium, Schlick takes the transmitted angle (the one on the less dense side).
TEST_F(FresnelProbe, SchlickDielectricUsesTransmittedAngleWhenLeaving)
{
    std::vector<FresnelCase> cases;
    for (float ior : kIors) {
        if (ior == 1.0f) continue;
        for (float c : cosineGrid(1000))
            if (sin2TransmittedRef(c, ior, 1.0) < 0.9) cases.push_back({c, ior, ior});
    }
    std::vector<FresnelResult> results = runFresnel(cases);
    for (size_t i = 0; i < cases.size(); ++i) {
        const FresnelCase& c = cases[i];
        double cosT = std::sqrt(1.0 - sin2TransmittedRef(c.cosI, c.eta, 1.0));
        EXPECT_TRUE(closeTo(results[i].schlickDielectric, schlickRef(cosT, schlickR0Ref(c.ior)), 1e-5)) << describe(c);
        EXPECT_EQ(results[i].reflectanceSchlick, results[i].schlickDielectric) << describe(c);
    }
}

// ---------------------------------------------------------------------------
// 2. Exact Fresnel

TEST_F(FresnelProbe, ExactMatchesTextbookFormulaEnteringAndLeaving)
{
    std::vector<FresnelCase> cases;
    for (float ior : kIors) {
        if (ior == 1.0f) continue;
        for (float c : cosineGrid(1000)) {
            cases.push_back({c, 1.0f / ior, ior}); // entering the denser medium
            // Leaving it: stay clear of the critical angle, where cos t = sqrt(1 - sin^2 t)
            // amplifies float32 rounding without bound (total internal reflection is test 3).
            if (sin2TransmittedRef(c, ior, 1.0) < 0.99) cases.push_back({c, ior, ior});
        }
    }
    std::vector<FresnelResult> results = runFresnel(cases);
    double worst = 0.0;
    for (size_t i = 0; i < cases.size(); ++i) {
        const FresnelCase& c = cases[i];
        // eta = n_i / n_t exactly as the GPU saw it (1 / ior is rounded to float).
        double expected = fresnelExactRef(c.cosI, c.eta, 1.0);
        EXPECT_TRUE(closeTo(results[i].exact, expected, 1e-5)) << describe(c);
        EXPECT_EQ(results[i].reflectanceExact, results[i].exact) << describe(c);
        worst = std::max(worst, std::abs(results[i].exact - expected) / expected);
        if (c.cosI == 1.0f) {
            EXPECT_TRUE(closeTo(results[i].exact, schlickR0Ref(c.ior), 1e-5)) << describe(c);
        }
        if (c.cosI == 0.0f) {
            EXPECT_EQ(results[i].exact, 1.0f) << describe(c);
        }
    }
    reportStat("ExactMaxRelativeError", worst);
}

// An index-matched interface (IOR 1) is no interface: exactly 0 at every angle,
// grazing included. (Evaluating the general formula in float32 would not give
// that: sin2T = 1 - cos^2 cancels badly for small cosines, leaving up to ~1e-5 at
// cos = 0.001, and cos = 0 gives sin2T = 1, the total internal reflection branch.)
TEST_F(FresnelProbe, ExactIsZeroForIndexMatchedInterface)
{
    std::vector<FresnelCase> cases;
    for (float c : cosineGrid(1000)) cases.push_back({c, 1.0f, 1.0f});
    std::vector<FresnelResult> results = runFresnel(cases);
    for (size_t i = 0; i < cases.size(); ++i) {
        EXPECT_EQ(results[i].exact, 0.0f) << describe(cases[i]);
        EXPECT_EQ(results[i].reflectanceExact, 0.0f) << describe(cases[i]);
    }
}

// ---------------------------------------------------------------------------
// 3. Total internal reflection, leaving glass (eta = 1.5)

TEST_F(FresnelProbe, TotalInternalReflectionAtAndBeyondCriticalAngle)
{
    const float eta = 1.5f;
    // Largest float cosine whose exact sin^2 t = eta^2 (1 - cos^2) is >= 1: the float
    // input at (or the first one beyond) the critical angle. In double the product is
    // exact (24-bit cos, 48-bit cos^2, eta^2 = 9/4).
    auto sin2T = [&](float c) { return double(eta) * double(eta) * (1.0 - double(c) * double(c)); };
    float critical = float(std::sqrt(1.0 - 1.0 / (double(eta) * eta)));
    while (sin2T(critical) < 1.0) critical = std::nextafter(critical, 0.0f);
    while (sin2T(std::nextafter(critical, 1.0f)) >= 1.0) critical = std::nextafter(critical, 1.0f);
    ASSERT_GE(sin2T(critical), 1.0);
    ASSERT_LT(sin2T(std::nextafter(critical, 1.0f)), 1.0);

    std::vector<FresnelCase> tir;
    float c = critical;
    for (int k = 0; k < 16; ++k, c = std::nextafter(c, 0.0f)) tir.push_back({c, eta, eta}); // just beyond
    for (float g : cosineGrid(1000))
        if (g < critical) tir.push_back({g, eta, eta}); // well beyond, down to grazing
    // Just inside: sin^2 t = 1 - 1e-4, far more than float rounding from the limit.
    float inside = float(std::sqrt(1.0 - (1.0 - 1e-4) / (double(eta) * eta)));
    std::vector<FresnelCase> cases = tir;
    cases.push_back({inside, eta, eta});

    std::vector<FresnelResult> results = runFresnel(cases);
    for (size_t i = 0; i < tir.size(); ++i) {
        EXPECT_EQ(results[i].exact, 1.0f) << describe(cases[i]);
        EXPECT_EQ(results[i].schlickDielectric, 1.0f) << describe(cases[i]);
        EXPECT_EQ(results[i].reflectanceExact, 1.0f) << describe(cases[i]);
    }
    const FresnelResult& in = results.back();
    EXPECT_LT(in.exact, 1.0f);
    EXPECT_LT(in.schlickDielectric, 1.0f);
    EXPECT_TRUE(std::isfinite(in.exact) && std::isfinite(in.schlickDielectric));
    // Close to the limit the value is ill-conditioned in float; only loosely compare.
    EXPECT_TRUE(closeTo(in.exact, fresnelExactRef(inside, eta, 1.0), 1e-3)) << describe(cases.back());
    reportStat("CriticalCosine", critical);
}

// ---------------------------------------------------------------------------
// 4. Cosines a rounding step (or more) outside [0, 1]

TEST_F(FresnelProbe, CosinesOutsideUnitIntervalGiveFiniteReflectance)
{
    const std::array<float, 4> outside = {-1e-7f, 1.0f + 1e-6f, -0.5f, 2.0f};
    std::vector<FresnelCase> cases;
    for (float ior : kIors)
        for (float eta : {1.0f / ior, ior})
            for (float c : outside) {
                cases.push_back({c, eta, ior});
                cases.push_back({std::clamp(c, 0.0f, 1.0f), eta, ior}); // what it is clamped to
            }
    std::vector<FresnelResult> results = runFresnel(cases);
    for (size_t i = 0; i < cases.size(); i += 2) {
        const FresnelResult& r = results[i];
        const FresnelResult& clamped = results[i + 1];
        for (float v : {r.schlick, r.exact, r.schlickDielectric, r.reflectanceExact, r.reflectanceSchlick}) {
            EXPECT_TRUE(std::isfinite(v)) << describe(cases[i]);
            EXPECT_GE(v, 0.0f) << describe(cases[i]);
            EXPECT_LE(v, 1.0f) << describe(cases[i]);
        }
        // The library documents clamping to [0, 1].
        EXPECT_EQ(r.schlick, clamped.schlick) << describe(cases[i]);
        EXPECT_EQ(r.exact, clamped.exact) << describe(cases[i]);
        EXPECT_EQ(r.schlickDielectric, clamped.schlickDielectric) << describe(cases[i]);
    }
}

// ---------------------------------------------------------------------------
// 5. Snell's law through sampleDielectric (tests/gpu/kernels/refraction_probe.comp)

class SnellProbe : public GpuTest {};

struct RefractionCase {
    glm::vec3 wo;      ///< towards the viewer
    glm::vec3 outward; ///< outward surface normal
    float ior;
};

TEST_F(SnellProbe, RefractionObeysSnellOrReflectsBeyondCriticalAngle)
{
    std::mt19937 rng(20240611u);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::normal_distribution<double> gauss;
    auto randomUnit = [&] {
        glm::dvec3 v(gauss(rng), gauss(rng), gauss(rng));
        return glm::normalize(v);
    };

    std::vector<RefractionCase> cases;
    for (float ior : {1.33f, 1.5f, 2.4f})
        for (bool entering : {true, false})
            for (int k = 0; k < 1500; ++k) {
                glm::dvec3 outward = randomUnit();
                glm::dvec3 side = entering ? outward : -outward; // the normal on wo's side
                glm::dvec3 t = glm::normalize(
                    glm::cross(side, std::abs(side.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
                glm::dvec3 b = glm::cross(side, t);
                // sin(theta_i) over [0, 1), plus exact normal incidence.
                double sinI = k == 0 ? 0.0 : 0.9999 * uniform(rng);
                double phi = 2.0 * M_PI * uniform(rng);
                glm::dvec3 wo = std::sqrt(1.0 - sinI * sinI) * side + sinI * (std::cos(phi) * t + std::sin(phi) * b);
                cases.push_back({glm::vec3(wo), glm::vec3(outward), ior});
            }

    std::vector<float> input;
    for (const RefractionCase& c : cases)
        input.insert(input.end(), {c.wo.x, c.wo.y, c.wo.z, c.outward.x, c.outward.y, c.outward.z, c.ior});
    std::vector<float> out = runProbe("refraction_probe", input, 4 * cases.size(), uint32_t(cases.size()));

    int refracted = 0, reflected = 0;
    double worstSnell = 0.0, worstPlane = 0.0, worstLength = 0.0, worstMirror = 0.0;
    for (size_t i = 0; i < cases.size(); ++i) {
        const RefractionCase& c = cases[i];
        // References from the float inputs exactly as the GPU saw them.
        glm::dvec3 wo = glm::normalize(glm::dvec3(c.wo));
        glm::dvec3 outward = glm::normalize(glm::dvec3(c.outward));
        bool entering = glm::dot(wo, outward) > 0.0;
        glm::dvec3 n = entering ? outward : -outward;
        double n1 = entering ? 1.0 : double(c.ior), n2 = entering ? double(c.ior) : 1.0;
        double sinI = glm::length(glm::cross(wo, n));
        double ratio = n1 * sinI / n2; // sin(theta_t); >= 1 is total internal reflection

        glm::dvec3 dir(out[4 * i], out[4 * i + 1], out[4 * i + 2]);
        float transmitted = out[4 * i + 3];
        std::string what = "case " + std::to_string(i) + " ior " + std::to_string(c.ior) +
                           (entering ? " entering" : " leaving") + " sin(theta_i) " + std::to_string(sinI);
        ASSERT_TRUE(std::isfinite(dir.x) && std::isfinite(dir.y) && std::isfinite(dir.z)) << what;
        double length = glm::length(dir);
        worstLength = std::max(worstLength, std::abs(length - 1.0));
        EXPECT_NEAR(length, 1.0, 1e-5) << what;

        // Within float rounding of the critical angle either outcome is right.
        if (std::abs(ratio - 1.0) > 1e-4) {
            EXPECT_EQ(transmitted, ratio < 1.0 ? 1.0f : 0.0f) << what;
        }
        if (transmitted == 1.0f) {
            ++refracted;
            EXPECT_LT(glm::dot(dir, n), 0.0) << what << ": refracted ray stays on the incident side";
            double sinT = glm::length(glm::cross(dir, n)) / length;
            double snell = std::abs(n1 * sinI - n2 * sinT);
            worstSnell = std::max(worstSnell, snell);
            EXPECT_LE(snell, 1e-5) << what << " sin(theta_t) " << sinT;
            double plane = std::abs(glm::dot(glm::cross(-wo, n), dir));
            worstPlane = std::max(worstPlane, plane);
            EXPECT_LE(plane, 1e-5) << what << ": out of the plane of incidence";
        } else {
            ASSERT_EQ(transmitted, 0.0f) << what;
            ++reflected;
            glm::dvec3 mirror = -wo + 2.0 * glm::dot(n, wo) * n;
            double mirrorError = glm::length(dir - mirror);
            worstMirror = std::max(worstMirror, mirrorError);
            EXPECT_LE(mirrorError, 1e-5) << what << ": not the mirror direction";
        }
    }
    // Both branches must have been exercised.
    EXPECT_GT(refracted, 1000);
    EXPECT_GT(reflected, 1000);
    reportStat("Refracted", refracted);
    reportStat("Reflected", reflected);
    reportStat("WorstSnellResidual", worstSnell);
    reportStat("WorstPlaneResidual", worstPlane);
    reportStat("WorstLengthError", worstLength);
    reportStat("WorstMirrorError", worstMirror);
}

// ---------------------------------------------------------------------------
// 6. Uniform triangle sampling

struct Triangle {
    glm::dvec3 a, b, c;
};

// Scalene, not axis-aligned, away from the origin.
const Triangle kTriangle{{0.3, -1.2, 2.0}, {4.1, 0.5, -0.7}, {-1.5, 3.3, 1.1}};

/// Barycentric coordinates (of A, B, C) of p projected onto the triangle's plane,
/// and p's distance from that plane.
struct Barycentric {
    double a, b, c;
    double planeDistance;
};

Barycentric barycentric(const Triangle& t, const glm::dvec3& p)
{
    glm::dvec3 e1 = t.b - t.a, e2 = t.c - t.a, d = p - t.a;
    double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
    double d1 = glm::dot(d, e1), d2 = glm::dot(d, e2);
    double det = d11 * d22 - d12 * d12;
    double b = (d22 * d1 - d12 * d2) / det, c = (d11 * d2 - d12 * d1) / det;
    glm::dvec3 normal = glm::normalize(glm::cross(e1, e2));
    return {1.0 - b - c, b, c, glm::dot(d, normal)};
}

struct UniformityResult {
    double chiSquare = 0.0;
    int dof = 0;
    double pValue = 0.0;
};

/// Chi-square test of the points' barycentrics against the uniform density: the
/// barycentric (b, c) triangle is cut by a K x K grid into K^2 equal-area cells,
/// the lower (i, j) and upper (i, j) triangles, each 1 / K^2 of the area.
UniformityResult chiSquareUniformity(const std::vector<Barycentric>& points, int k)
{
    // counts[(upper * k + i) * k + j]; lower cells exist for i + j <= k - 1, upper ones for i + j <= k - 2.
    std::vector<int64_t> counts(2 * size_t(k) * k, 0);
    for (const Barycentric& p : points) {
        double u = p.b * k, v = p.c * k;
        int i = std::clamp(int(std::floor(u)), 0, k - 1);
        int j = std::clamp(int(std::floor(v)), 0, k - 1 - i);
        bool upper = (u - i) + (v - j) >= 1.0 && i + j <= k - 2;
        ++counts[(size_t(upper) * k + i) * k + j];
    }
    UniformityResult result;
    double expected = double(points.size()) / (double(k) * k);
    int cells = 0;
    for (int upper = 0; upper < 2; ++upper)
        for (int i = 0; i < k; ++i)
            for (int j = 0; i + j <= k - 1 - upper; ++j, ++cells)
                result.chiSquare += square(double(counts[(size_t(upper) * k + i) * k + j]) - expected) / expected;
    result.dof = cells - 1;
    result.pValue = chiSquarePValue(result.chiSquare, result.dof);
    return result;
}

/// sqrt(n) * D of the one-sample Kolmogorov-Smirnov test of the barycentric
/// coordinate of A against its CDF for uniform points, F(s) = 1 - (1 - s)^2.
double ksStatisticOfVertexCoordinate(const std::vector<Barycentric>& points)
{
    std::vector<double> s;
    s.reserve(points.size());
    for (const Barycentric& p : points) s.push_back(p.a);
    std::sort(s.begin(), s.end());
    double n = double(s.size()), d = 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
        double x = std::clamp(s[i], 0.0, 1.0);
        double f = 1.0 - square(1.0 - x);
        d = std::max({d, f - double(i) / n, double(i + 1) / n - f});
    }
    return std::sqrt(n) * d;
}

constexpr uint32_t kSampleCount = 1000000;
constexpr int kGrid = 16;            // 256 cells, ~3906 expected points each
constexpr double kKsCritical = 1.63; // sqrt(n) D at alpha = 0.01
constexpr double kSignificance = 0.01;

/// The GPU's points (sampleTriangle with the render kernels' sampler), computed once.
const std::vector<glm::dvec3>& gpuTrianglePoints()
{
    static const std::vector<glm::dvec3> points = [] {
        const Triangle& t = kTriangle;
        std::vector<float> input;
        for (const glm::dvec3& v : {t.a, t.b, t.c}) input.insert(input.end(), {float(v.x), float(v.y), float(v.z)});
        input.push_back(7919.0f); // seed (exact in float)
        std::vector<float> out = runProbe("triangle_sampler_probe", input, 3 * size_t(kSampleCount), kSampleCount);
        std::vector<glm::dvec3> result(kSampleCount);
        for (size_t i = 0; i < kSampleCount; ++i) result[i] = glm::dvec3(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
        return result;
    }();
    return points;
}

/// The triangle as the GPU saw it (vertices rounded to float).
Triangle floatTriangle()
{
    return {glm::dvec3(glm::vec3(kTriangle.a)), glm::dvec3(glm::vec3(kTriangle.b)), glm::dvec3(glm::vec3(kTriangle.c))};
}

std::vector<Barycentric> barycentrics(const Triangle& t, const std::vector<glm::dvec3>& points)
{
    std::vector<Barycentric> result;
    result.reserve(points.size());
    for (const glm::dvec3& p : points) result.push_back(barycentric(t, p));
    return result;
}

/// The classic mistake: P = (1 - x1) A + x1 (1 - x2) B + x1 x2 C, without the
/// square root, which crowds points towards A.
glm::dvec3 sampleTriangleWithoutSqrt(const Triangle& t, double x1, double x2)
{
    return (1.0 - x1) * t.a + x1 * (1.0 - x2) * t.b + x1 * x2 * t.c;
}

std::vector<glm::dvec3> wrongSamplerPoints(const Triangle& t)
{
    std::mt19937 rng(12345u);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<glm::dvec3> points(kSampleCount);
    for (glm::dvec3& p : points) {
        double x1 = uniform(rng);
        double x2 = uniform(rng);
        p = sampleTriangleWithoutSqrt(t, x1, x2);
    }
    return points;
}

class TriangleSamplerProbe : public GpuTest {};

// The statistics helper itself, against chi-square table values.
TEST_F(TriangleSamplerProbe, ChiSquarePValueMatchesTables)
{
    EXPECT_NEAR(chiSquarePValue(4.0, 2), std::exp(-2.0), 1e-12); // dof 2: exp(-x/2)
    EXPECT_NEAR(chiSquarePValue(23.209, 10), 0.01, 1e-4);
    EXPECT_NEAR(chiSquarePValue(3.841, 1), 0.05, 1e-4);
    EXPECT_NEAR(chiSquarePValue(310.457, 255), 0.01, 2e-4);
    EXPECT_NEAR(chiSquarePValue(254.335, 255), 0.5, 2e-3);
    EXPECT_NEAR(chiSquarePValue(1.0, 255), 1.0, 1e-12);
    EXPECT_LT(chiSquarePValue(1000.0, 255), 1e-30);
}

TEST_F(TriangleSamplerProbe, PointsLieInTheTriangleAndAreUniform)
{
    Triangle t = floatTriangle();
    std::vector<Barycentric> points = barycentrics(t, gpuTrianglePoints());
    double scale = std::max({glm::length(t.a), glm::length(t.b), glm::length(t.c)});
    double worstPlane = 0.0, worstInside = std::numeric_limits<double>::infinity();
    int64_t outside = 0, offPlane = 0;
    for (const Barycentric& p : points) {
        worstPlane = std::max(worstPlane, std::abs(p.planeDistance));
        worstInside = std::min({worstInside, p.a, p.b, p.c});
        if (std::abs(p.planeDistance) > 1e-5 * scale) ++offPlane;
        if (std::min({p.a, p.b, p.c}) < -1e-5) ++outside;
    }
    EXPECT_EQ(offPlane, 0) << "worst distance from the plane " << worstPlane;
    EXPECT_EQ(outside, 0) << "most negative barycentric " << worstInside;

    UniformityResult chi = chiSquareUniformity(points, kGrid);
    EXPECT_GT(chi.pValue, kSignificance) << "chi-square " << chi.chiSquare << " with " << chi.dof << " dof";
    reportStat("ChiSquare", chi.chiSquare);
    reportStat("PValue", chi.pValue);
    reportStat("WorstPlaneDistance", worstPlane);
    reportStat("MostNegativeBarycentric", worstInside);
}

TEST_F(TriangleSamplerProbe, VertexCoordinateFollowsItsMarginal)
{
    std::vector<Barycentric> points = barycentrics(floatTriangle(), gpuTrianglePoints());
    double ks = ksStatisticOfVertexCoordinate(points);
    EXPECT_LT(ks, kKsCritical);
    reportStat("KsStatistic", ks);
}

// The two tests above reject a sampler with the classic mistake, so they can fail.
TEST_F(TriangleSamplerProbe, TestsRejectSamplerWithoutSquareRoot)
{
    std::vector<Barycentric> points = barycentrics(kTriangle, wrongSamplerPoints(kTriangle));
    for (const Barycentric& p : points) ASSERT_GE(std::min({p.a, p.b, p.c}), -1e-9); // still inside
    UniformityResult chi = chiSquareUniformity(points, kGrid);
    EXPECT_LT(chi.pValue, kSignificance) << "chi-square " << chi.chiSquare;
    double ks = ksStatisticOfVertexCoordinate(points);
    EXPECT_GT(ks, kKsCritical);
    reportStat("WrongChiSquare", chi.chiSquare);
    reportStat("WrongPValue", chi.pValue);
    reportStat("WrongKsStatistic", ks);
}

// ---------------------------------------------------------------------------
// accurateAcos (sampling.glsl): the lat-long map's theta, so that the image
// does not depend on how far a conformant driver's acos is off (4096 ulp).

TEST(AccurateAcosProbe, IsWithinTwoUlpOfPiEverywhere)
{
    std::vector<float> inputs;
    for (int k = -4000; k <= 4000; ++k) inputs.push_back(float(k) / 4000.0f);
    for (float x : {1.0f - 1e-7f, 1.0f - 6e-8f, -1.0f + 6e-8f, 0.9999f, -0.9999f, 1e-20f, -0.0f, 2.0f, -2.0f})
        inputs.push_back(x);
    const std::vector<float> out = runProbe("acos_probe", inputs, inputs.size(), uint32_t(inputs.size()));
    double worst = 0.0;
    for (size_t i = 0; i < inputs.size(); ++i) {
        const double x = std::clamp(double(inputs[i]), -1.0, 1.0), want = std::acos(x);
        worst = std::max(worst, std::abs(out[i] - want));
        EXPECT_NEAR(out[i], want, 5e-7) << "acos(" << inputs[i] << ")";
    }
    std::cout << "accurateAcos: largest error " << worst << " rad\n";
}

} // namespace
} // namespace vkrt::test
