#pragma once
// Chi-square goodness-of-fit of sampled directions against a density over the sphere (the practice of
// Mitsuba's and pbrt's BSDF tests): cells in (cos theta, phi), expected counts by adaptive integration of
// the pdf over each cell, cells with small expected counts pooled, p-value from the incomplete gamma.
// Used by the CPU reference-BSDF tests and, with directions read back from a probe kernel, by GPU tests.
#include <functional>
#include <glm/vec3.hpp>
#include <span>
#include <string>

namespace vkrt::test {

/// Solid-angle density of a direction (unit vector, any hemisphere); integrates to <= 1 over the sphere.
using DirectionPdf = std::function<double(const glm::dvec3&)>;

struct ChiSquareOptions {
    int thetaBins = 20;          ///< cells in cos(theta) over [-1, 1]; phi gets twice as many over [0, 2 pi)
    int subCells = 4;            ///< initial Simpson panels per cell and axis before adaptive refinement
    double countTolerance = 0.1;  ///< error allowed in each cell's expected count (sets the integration tolerance)
    double minExpected = 5.0;    ///< cells expecting fewer samples are pooled together
    int worstCellsShown = 8;     ///< rows in the printable table
};

struct ChiSquareResult {
    double pValue = 0.0;        ///< probability of a statistic at least this large if the sampler is right
    double statistic = 0.0;
    int degreesOfFreedom = 0;
    double integratedPdf = 0.0; ///< integral of the pdf over the sphere (1 - mass of rejected samples)
    std::string table;          ///< the cells contributing most, for failure messages
    /// The test passes at significance level alpha (already corrected for the number of tests).
    bool passes(double alpha) const { return pValue >= alpha; }
};

/// Tests `samples` (unit directions) plus `rejected` draws that produced no direction (zero weight, below
/// the surface) against `pdf`: the rejected draws are one more cell, expecting N (1 - integral of pdf).
ChiSquareResult chiSquareTest(std::span<const glm::dvec3> samples, long long rejected, const DirectionPdf& pdf,
                              const ChiSquareOptions& options = {});
/// The same for single-precision directions, as a probe kernel writes them.
ChiSquareResult chiSquareTest(std::span<const glm::vec3> samples, long long rejected, const DirectionPdf& pdf,
                              const ChiSquareOptions& options = {});

/// Regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a) (a > 0, x >= 0).
double upperIncompleteGammaQ(double a, double x);

/// P(chi^2_dof >= statistic).
double chiSquarePValue(double statistic, int degreesOfFreedom);

/// Per-test significance so that `tests` independent tests together reject a right sampler with
/// probability alpha (Sidak: 1 - (1 - alpha)^(1 / tests)).
double sidakCorrectedAlpha(double alpha, int tests);

/// Adaptive Simpson integral of f(u, v) over [u0, u1] x [v0, v1] starting from n x n panels.
double integrate2d(const std::function<double(double, double)>& f, double u0, double u1, double v0, double v1,
                   int n, double tolerance);

} // namespace vkrt::test
