#pragma once
// Image error measures (docs/convergence.md): estimated from a render's own
// variance, or measured against a reference.
#include "io/Image.h"

#include <cmath>
#include <cstddef>

namespace vkrt {

/// The epsilon in relMSE = (x - r)^2 / (r^2 + epsilon): keeps black pixels
/// from dominating (the convention of Rousselle et al. and Mitsuba's tests).
inline constexpr double kRelMseEpsilon = 0.01;

struct EstimatedError {
    double rmse = 0.0;   ///< sqrt(mean over values of Var[mean])
    double relMse = 0.0; ///< mean of Var[mean] / (max(|mean| - sigma, 0)^2 + epsilon), sigma = sqrt(Var[mean])
    /// A one-sided upper confidence bound on relMse (kRelMseConfidence): relMse
    /// times nu / chi2_{1 - confidence}(nu), nu its degrees of freedom below.
    double relMseUpper = 0.0;
    /// relMse's effective degrees of freedom (Welch-Satterthwaite over the
    /// values' terms, each with the per-pixel variance's degrees of freedom):
    /// few where a handful of pixels carry the estimate, many where it is spread.
    double degreesOfFreedom = 0.0;
};

/// The confidence of EstimatedError::relMseUpper, the bound --target-error stops on.
inline constexpr double kRelMseConfidence = 0.95;

/// From per-pixel variance of the mean, estimated with `pixelDegreesOfFreedom`
/// (VARIANCE_BATCHES - 1 from batch means, spp - 1 from independent samples);
/// non-finite values and variances are skipped.
///
/// The relMSE's denominator is the true value squared, which the render only
/// estimates. Its own mean squared overstates it where a rare bright sample
/// (a firefly) raised both mean and variance, and so understates the error
/// exactly where it is largest (measured: 3-8x too low on the glossy
/// validation scenes). The value one standard error below the mean is a lower
/// confidence bound on the true value; squared, it keeps a firefly pixel's
/// term large and converges to the mean as the noise falls (docs/convergence.md).
EstimatedError estimateError(const Image& mean, const Image& varianceOfMean, double pixelDegreesOfFreedom);

/// nu / chi2_{1 - confidence}(nu): a variance estimated with nu degrees of
/// freedom times this is its one-sided upper confidence bound (1 at nu = inf,
/// +inf at nu <= 0).
double varianceUpperFactor(double degreesOfFreedom, double confidence);

struct MeasuredError {
    double rmse = 0.0;
    double relMse = 0.0;
    double mape = 0.0;     ///< mean of |x - r| / (|r| + epsilon)
    double maxAbs = 0.0;   ///< largest |x - r|
    size_t nonFiniteA = 0; ///< non-finite values in the image
    size_t nonFiniteB = 0; ///< non-finite values in the reference
    size_t compared = 0;   ///< values where both are finite
};

/// `image` against `reference` (same size: checked by the caller).
MeasuredError measureError(const Image& image, const Image& reference);

/// Per-pixel two-sided test of equal means, t = (a - b) / sqrt(va + vb),
/// with a Sidak correction of alpha over all tested values. With variances
/// known to many degrees of freedom (dof = +inf: the default) t is normal (a
/// Z-test); with few, e.g. a variance from 8 batch means (7), it is Welch's
/// test, Student's t with the Welch-Satterthwaite degrees of freedom
/// (va + vb)^2 / (va^2 / dofA + vb^2 / dofB).
struct PixelTestSummary {
    size_t tested = 0;
    size_t passed = 0;
    double threshold = 0.0;  ///< per-value p-value limit after the correction
    double zThreshold = 0.0; ///< the same limit as |t| for a normal t (infinite dof)
    double minPValue = 1.0;  ///< smallest two-sided p-value
    double fractionPassed() const { return tested ? double(passed) / double(tested) : 1.0; }
};

PixelTestSummary pixelZTest(const Image& a, const Image& varianceA, const Image& b, const Image& varianceB,
                            double alpha = 0.01, double dofA = INFINITY, double dofB = INFINITY);

/// P(|T| > t) for Student's t with `dof` degrees of freedom (> 0; +inf: normal).
double studentTwoSidedTail(double t, double dof);

/// A render against a reference, the rule of the validation and regression
/// suites (docs/validation.md). Per value, z = (x - r) / sigma with
///   sigma^2 = max(Var_x, Var_r * refSpp / spp) + Var_r + (1e-6 r)^2:
/// the reference's per-sample variance, scaled to the render's spp, is a floor
/// under the render's own estimate (a rare-event pixel can show zero sample
/// variance at low spp), and the last term absorbs float rounding of
/// deterministic pixels. It passes when at least `minFraction` of the values
/// pass a Sidak-corrected two-sided test at `alpha`, and the pooled z of the
/// summed difference stays within the two-sided `pooledAlpha` quantile (a
/// small bias everywhere, invisible per pixel, shows there).
struct ReferenceTestResult {
    size_t tested = 0, passed = 0;
    double threshold = 0.0; ///< per-value |z| limit
    double pooledZ = 0.0;
    double pooledThreshold = 0.0;
    double minPValue = 1.0;
    Image pValues; ///< per value, for failure reports
    double fractionPassed() const { return tested ? double(passed) / double(tested) : 1.0; }
    bool passedRule(double minFraction) const
    {
        return fractionPassed() >= minFraction && std::abs(pooledZ) <= pooledThreshold;
    }
};

struct ReferenceTestSettings {
    double alpha = 0.01;
    double pooledAlpha = 0.001;
    double minFraction = 0.9975;
};

ReferenceTestResult testAgainstReference(const Image& mean, const Image& varianceOfMean, uint32_t spp,
                                         const Image& reference, const Image& referenceVariance, uint64_t referenceSpp,
                                         const ReferenceTestSettings& settings = {});

/// Two-sided standard normal quantile: |z| with P(|Z| > |z|) = p.
double normalQuantileTwoSided(double p);

} // namespace vkrt
