#include "material/Fresnel.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>

namespace vkrt {

DielectricFresnel fresnelDielectric(double cosI, double eta)
{
    bool fromOutside = cosI >= 0.0;
    double etaIT = fromOutside ? eta : 1.0 / eta; // n_t / n_i along the direction of travel
    double etaTI = 1.0 / etaIT;
    double absCosI = std::min(std::abs(cosI), 1.0);
    double sin2T = (1.0 - absCosI * absCosI) * etaTI * etaTI;
    if (sin2T >= 1.0) return {1.0, 0.0, etaTI};
    double cosT = std::sqrt(1.0 - sin2T);
    if (eta == 1.0) return {0.0, cosT, etaTI};
    // Amplitudes of the s- and p-polarized reflected waves (Born & Wolf, eq. 1.5.20).
    double rs = (absCosI - etaIT * cosT) / (absCosI + etaIT * cosT);
    double rp = (etaIT * absCosI - cosT) / (etaIT * absCosI + cosT);
    return {0.5 * (rs * rs + rp * rp), cosT, etaTI};
}

double fresnelConductor(double cosI, double eta, double k)
{
    using Complex = std::complex<double>;
    cosI = std::clamp(cosI, 0.0, 1.0);
    Complex n(eta, k);
    double sin2I = 1.0 - cosI * cosI;
    // Snell's law with a complex index: cos of the (complex) refracted angle.
    Complex cosT = std::sqrt(1.0 - sin2I / (n * n));
    Complex rs = (cosI - n * cosT) / (cosI + n * cosT);
    Complex rp = (n * cosI - cosT) / (n * cosI + cosT);
    return 0.5 * (std::norm(rs) + std::norm(rp));
}

namespace {

/// Adaptive Simpson on [a, b] with Richardson's correction; fa, fm, fb are the end and mid values.
double adaptiveSimpson(const std::function<double(double)>& f, double a, double b, double fa, double fm,
                       double fb, double whole, double tolerance, int depth)
{
    double m = 0.5 * (a + b);
    double lm = f(0.5 * (a + m)), rm = f(0.5 * (m + b));
    double left = (m - a) / 6.0 * (fa + 4.0 * lm + fm);
    double right = (b - m) / 6.0 * (fm + 4.0 * rm + fb);
    double delta = left + right - whole;
    if (depth <= 0 || std::abs(delta) <= 15.0 * tolerance) return left + right + delta / 15.0;
    return adaptiveSimpson(f, a, m, fa, lm, fm, left, 0.5 * tolerance, depth - 1)
         + adaptiveSimpson(f, m, b, fm, rm, fb, right, 0.5 * tolerance, depth - 1);
}

double integrate(const std::function<double(double)>& f, double a, double b, double tolerance)
{
    double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
    double whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    return adaptiveSimpson(f, a, b, fa, fm, fb, whole, tolerance, 40);
}

} // namespace

double diffuseFresnelReflectance(double eta)
{
    auto weighted = [eta](double mu) { return 2.0 * fresnelDielectric(mu, eta).reflectance * mu; };
    // Split at the critical angle (eta < 1): F has a square-root kink there.
    double critical = eta < 1.0 ? std::sqrt(1.0 - eta * eta) : 0.0;
    double total = 0.0;
    if (critical > 0.0) total += critical * critical; // F = 1 below the critical cosine: 2 * integral mu
    total += integrate(weighted, critical, 1.0, 1e-13);
    return total;
}

} // namespace vkrt
