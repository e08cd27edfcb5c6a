// The spectral thin-film reference (see ThinFilmReference.h): wave optics of a
// single film (Born and Wolf, Principles of Optics, 7th ed., section 1.6.4)
// and the CIE fit of Wyman, Sloan and Shirley; nothing here comes from
// shaders/lib/iridescence.glsl or the glTF specification's approximation.
#include "support/ThinFilmReference.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

namespace vkrt::test {
namespace {

using Complex = std::complex<double>;

constexpr double kPi = std::numbers::pi;

/// cos(theta_j) in a layer of IOR nj for light entering from n1 at sin^2(theta_1) = sin2: complex beyond the
/// critical angle, with a positive imaginary part so that the evanescent wave decays (e^{i phi} -> 0).
Complex layerCosine(double n1, double nj, double sin2)
{
    double ratio = n1 / nj;
    return std::sqrt(Complex(1.0 - ratio * ratio * sin2, 0.0));
}

/// Fresnel's amplitude reflection coefficients of the interface a -> b, r_s = (na ca - nb cb) / (na ca + nb cb)
/// and r_p = (nb ca - na cb) / (nb ca + na cb): the convention in which the Airy sum has the same form for s and p.
struct Amplitudes {
    Complex s;
    Complex p;
};

Amplitudes interfaceAmplitudes(double na, Complex ca, double nb, Complex cb)
{
    if (na == nb) return {}; // no interface (the formulas are 0 / 0 at grazing incidence)
    return {(na * ca - nb * cb) / (na * ca + nb * cb), (nb * ca - na * cb) / (nb * ca + na * cb)};
}

/// The limit nb -> infinity of interfaceAmplitudes: a perfect mirror (F0 = 1).
Amplitudes mirrorAmplitudes() { return {Complex(-1.0), Complex(1.0)}; }

/// The Airy sum of a film between two interfaces, |r12 + r23 e^{i phi}|^2 / |1 + r12 r23 e^{i phi}|^2.
double airyReflectance(Complex r12, Complex r23, Complex phase)
{
    Complex e = std::exp(Complex(0.0, 1.0) * phase);
    return std::norm(r12 + r23 * e) / std::norm(1.0 + r12 * r23 * e);
}

/// exp(-1/2 t^2), t = (x - mu) times the inverse width on x's side of mu (Wyman et al., equation 2).
double piecewiseGaussian(double x, double mu, double inverseWidthBelow, double inverseWidthAbove)
{
    double t = (x - mu) * (x < mu ? inverseWidthBelow : inverseWidthAbove);
    return std::exp(-0.5 * t * t);
}

/// Sum of ybar over the integration grid: the normalisation that makes reflectance 1 give Y = 1.
double luminanceOfEqualEnergy()
{
    double sum = 0.0;
    for (int nm = kFirstWavelengthNm; nm <= kLastWavelengthNm; ++nm) sum += cieXyzMatching(nm).y;
    return sum;
}

} // namespace

double baseIorFromF0(double baseF0)
{
    if (baseF0 >= 1.0) return std::numeric_limits<double>::infinity();
    double s = std::sqrt(std::max(baseF0, 0.0));
    return (1.0 + s) / (1.0 - s);
}

double dielectricFresnel(double n1, double n2, double cosTheta)
{
    double c1 = std::clamp(cosTheta, 0.0, 1.0);
    double sin2 = 1.0 - c1 * c1;
    if (std::isinf(n2)) return 1.0;
    Complex c2 = layerCosine(n1, n2, sin2);
    if (c2.imag() > 0.0 || c2.real() == 0.0) return 1.0; // total internal reflection
    Amplitudes r = interfaceAmplitudes(n1, Complex(c1), n2, c2);
    return 0.5 * (std::norm(r.s) + std::norm(r.p));
}

double thinFilmReflectance(const ThinFilm& film, double cosTheta, double wavelengthNm)
{
    double n1 = film.outsideIor, n2 = film.filmIor, n3 = baseIorFromF0(film.baseF0);
    if (film.thicknessNm == 0.0) return dielectricFresnel(n1, n3, cosTheta); // the film's limit, without 0 / 0
    double c1 = std::clamp(cosTheta, 0.0, 1.0);
    double sin2 = 1.0 - c1 * c1;
    Complex c2 = layerCosine(n1, n2, sin2);
    Amplitudes top = interfaceAmplitudes(n1, Complex(c1), n2, c2);
    Amplitudes bottom =
        std::isinf(n3) ? mirrorAmplitudes() : interfaceAmplitudes(n2, c2, n3, layerCosine(n1, n3, sin2));
    // Phase of one round trip through the film (complex, i.e. decaying, when the film's wave is evanescent).
    Complex phase = 4.0 * kPi * n2 * film.thicknessNm * c2 / wavelengthNm;
    return 0.5 * (airyReflectance(top.s, bottom.s, phase) + airyReflectance(top.p, bottom.p, phase));
}

glm::dvec3 cieXyzMatching(double nm)
{
    double x = 0.362 * piecewiseGaussian(nm, 442.0, 0.0624, 0.0374) +
               1.056 * piecewiseGaussian(nm, 599.8, 0.0264, 0.0323) -
               0.065 * piecewiseGaussian(nm, 501.1, 0.0490, 0.0382);
    double y =
        0.821 * piecewiseGaussian(nm, 568.8, 0.0213, 0.0247) + 0.286 * piecewiseGaussian(nm, 530.9, 0.0613, 0.0322);
    double z =
        1.217 * piecewiseGaussian(nm, 437.0, 0.0845, 0.0278) + 0.681 * piecewiseGaussian(nm, 459.0, 0.0385, 0.0725);
    return {x, y, z};
}

glm::dvec3 thinFilmXyz(const ThinFilm& film, double cosTheta)
{
    static const double norm = luminanceOfEqualEnergy();
    glm::dvec3 xyz(0.0);
    for (int nm = kFirstWavelengthNm; nm <= kLastWavelengthNm; ++nm)
        xyz += thinFilmReflectance(film, cosTheta, nm) * cieXyzMatching(nm);
    return xyz / norm;
}

glm::dvec3 xyzToLinearRec709(const glm::dvec3& xyz)
{
    // IEC 61966-2-1 (sRGB primaries, D65 white), rows.
    return {3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
            -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
            0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z};
}

glm::dvec3 equalEnergyRgb()
{
    glm::dvec3 xyz(0.0);
    for (int nm = kFirstWavelengthNm; nm <= kLastWavelengthNm; ++nm) xyz += cieXyzMatching(nm);
    return xyzToLinearRec709(xyz / xyz.y);
}

glm::dvec3 thinFilmRgb(const ThinFilm& film, double cosTheta, RgbWhite white)
{
    glm::dvec3 rgb = xyzToLinearRec709(thinFilmXyz(film, cosTheta));
    if (white == RgbWhite::Balanced) {
        static const glm::dvec3 equalEnergy = equalEnergyRgb();
        rgb /= equalEnergy;
    }
    return rgb;
}

} // namespace vkrt::test
