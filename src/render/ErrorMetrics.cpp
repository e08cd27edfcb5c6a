#include "render/ErrorMetrics.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <cmath>

namespace vkrt {

EstimatedError estimateError(const Image& mean, const Image& varianceOfMean, double pixelDegreesOfFreedom)
{
    double sumVariance = 0.0, sumRelative = 0.0, sumSquaredTerms = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < mean.rgb.size(); ++i) {
        double v = varianceOfMean.rgb[i], m = mean.rgb[i];
        if (!std::isfinite(v) || !std::isfinite(m)) continue;
        double lowerValue = std::max(std::abs(m) - std::sqrt(v), 0.0);
        double term = v / (lowerValue * lowerValue + kRelMseEpsilon);
        sumVariance += v;
        sumRelative += term;
        sumSquaredTerms += term * term;
        ++n;
    }
    if (n == 0 || !(pixelDegreesOfFreedom > 0.0)) return {INFINITY, INFINITY, INFINITY, 0.0};
    EstimatedError e;
    e.rmse = std::sqrt(sumVariance / double(n));
    e.relMse = sumRelative / double(n);
    if (sumRelative == 0.0) return e; // no noise anywhere: a bound of 0 too
    // Each term is its pixel's sigma^2 chi2_d / d: the sum's Satterthwaite
    // degrees of freedom are (sum t)^2 / sum(t^2 / d).
    e.degreesOfFreedom = std::isinf(pixelDegreesOfFreedom)
                             ? INFINITY
                             : sumRelative * sumRelative / (sumSquaredTerms / pixelDegreesOfFreedom);
    e.relMseUpper = e.relMse * varianceUpperFactor(e.degreesOfFreedom, kRelMseConfidence);
    return e;
}

double varianceUpperFactor(double degreesOfFreedom, double confidence)
{
    if (!(degreesOfFreedom > 0.0)) return INFINITY;
    if (std::isinf(degreesOfFreedom) || degreesOfFreedom > 1e7) return 1.0;
    boost::math::chi_squared chi2(degreesOfFreedom);
    return degreesOfFreedom / boost::math::quantile(chi2, 1.0 - confidence);
}

MeasuredError measureError(const Image& image, const Image& reference)
{
    MeasuredError e;
    double sumSq = 0.0, sumRel = 0.0, sumAbsRel = 0.0;
    for (size_t i = 0; i < image.rgb.size(); ++i) {
        double x = image.rgb[i], r = reference.rgb[i];
        bool finiteX = std::isfinite(x), finiteR = std::isfinite(r);
        e.nonFiniteA += !finiteX;
        e.nonFiniteB += !finiteR;
        if (!finiteX || !finiteR) continue;
        double d = x - r;
        sumSq += d * d;
        sumRel += d * d / (r * r + kRelMseEpsilon);
        sumAbsRel += std::abs(d) / (std::abs(r) + kRelMseEpsilon);
        e.maxAbs = std::max(e.maxAbs, std::abs(d));
        ++e.compared;
    }
    if (e.compared) {
        double n = double(e.compared);
        e.rmse = std::sqrt(sumSq / n);
        e.relMse = sumRel / n;
        e.mape = sumAbsRel / n;
    }
    return e;
}

double normalQuantileTwoSided(double p)
{
    // Bisection on erfc: P(|Z| > z) = erfc(z / sqrt 2), monotone in z.
    double lo = 0.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

ReferenceTestResult testAgainstReference(const Image& mean, const Image& varianceOfMean, uint32_t spp,
                                         const Image& reference, const Image& referenceVariance, uint64_t referenceSpp,
                                         const ReferenceTestSettings& settings)
{
    ReferenceTestResult r;
    size_t n = mean.rgb.size();
    r.pValues = Image(mean.width, mean.height);
    r.threshold = normalQuantileTwoSided(1.0 - std::pow(1.0 - settings.alpha, 1.0 / double(std::max<size_t>(n, 1))));
    r.pooledThreshold = normalQuantileTwoSided(settings.pooledAlpha);
    double sumDiff = 0.0, sumVariance = 0.0;
    double scale = double(referenceSpp) / double(std::max(spp, 1u));
    for (size_t i = 0; i < n; ++i) {
        double x = mean.rgb[i], ref = reference.rgb[i], vr = referenceVariance.rgb[i];
        double vx = std::isfinite(varianceOfMean.rgb[i]) ? double(varianceOfMean.rgb[i]) : INFINITY;
        double variance = std::max(vx, vr * scale) + vr + std::pow(1e-6 * ref, 2);
        // Equal values pass even with zero variance (a black background: 0/0).
        double z = x == ref ? 0.0 : std::abs(x - ref) / std::sqrt(variance);
        double p = (std::isfinite(x) && variance > 0.0) ? std::erfc(z / std::sqrt(2.0)) : (x == ref ? 1.0 : 0.0);
        r.pValues.rgb[i] = float(p);
        r.minPValue = std::min(r.minPValue, p);
        ++r.tested;
        if (std::isfinite(x) && z <= r.threshold) ++r.passed;
        if (std::isfinite(x) && std::isfinite(variance)) sumDiff += x - ref, sumVariance += variance;
    }
    r.pooledZ = sumVariance > 0.0 ? sumDiff / std::sqrt(sumVariance) : (sumDiff == 0.0 ? 0.0 : INFINITY);
    return r;
}

double studentTwoSidedTail(double t, double dof)
{
    t = std::abs(t);
    if (std::isinf(t)) return 0.0;
    if (!(dof > 0.0)) return 1.0; // a variance from no degrees of freedom rejects nothing
    // Beyond 1e7 degrees of freedom t and the normal differ by less than 1e-7.
    if (!(dof <= 1e7)) return std::erfc(t / std::sqrt(2.0));
    return 2.0 * boost::math::cdf(boost::math::complement(boost::math::students_t(dof), t));
}

namespace {

/// Welch-Satterthwaite degrees of freedom of va + vb.
double welchDegreesOfFreedom(double va, double dofA, double vb, double dofB)
{
    double termA = std::isinf(dofA) ? 0.0 : va * va / dofA, termB = std::isinf(dofB) ? 0.0 : vb * vb / dofB;
    double terms = termA + termB;
    return terms > 0.0 ? (va + vb) * (va + vb) / terms : INFINITY;
}

} // namespace

PixelTestSummary pixelZTest(const Image& a, const Image& varianceA, const Image& b, const Image& varianceB,
                            double alpha, double dofA, double dofB)
{
    PixelTestSummary s;
    size_t n = a.rgb.size();
    s.threshold = 1.0 - std::pow(1.0 - alpha, 1.0 / double(std::max<size_t>(n, 1)));
    s.zThreshold = normalQuantileTwoSided(s.threshold);
    for (size_t i = 0; i < n; ++i) {
        double d = double(a.rgb[i]) - b.rgb[i];
        double va = varianceA.rgb[i], vb = varianceB.rgb[i];
        double sigma = std::sqrt(va + vb);
        ++s.tested;
        if (!std::isfinite(d) || !std::isfinite(sigma)) continue; // a non-finite value fails
        double p = sigma > 0.0 ? studentTwoSidedTail(d / sigma, welchDegreesOfFreedom(va, dofA, vb, dofB))
                               : (d == 0.0 ? 1.0 : 0.0);
        s.minPValue = std::min(s.minPValue, p);
        if (p >= s.threshold) ++s.passed;
    }
    return s;
}

} // namespace vkrt
