#pragma once
// An independent double-precision reference for thin-film iridescence (the
// physics that KHR_materials_iridescence's Fresnel approximates;
// shaders/lib/iridescence.glsl): the exact reflectance of a three-layer
// dielectric stack outside / film / base, computed wavelength by wavelength
// and integrated to colour. Not derived from the GLSL or the specification's
// approximation:
//   - per wavelength, the Airy sum of all the film's inter-reflections with
//     complex amplitude coefficients (Fresnel's r_s and r_p, evanescent waves
//     included), R = |r12 + r23 e^{i phi}|^2 / |1 + r12 r23 e^{i phi}|^2,
//     phi = 4 pi n_film d cos(theta_film) / lambda, averaged over s and p;
//   - the base is a dielectric whose IOR is constant over wavelength, taken
//     from a grey F0 as the specification does, n = (1 + sqrt F0) / (1 - sqrt F0)
//     (F0 = 1 is a perfect mirror, r = -1 for s and +1 for p);
//   - colour: 380..780 nm in 1 nm steps against the CIE 1931 2-degree
//     colour-matching functions in the analytic multi-lobe piecewise-Gaussian
//     fit of Wyman, Sloan and Shirley (JCGT 2(2), 2013; no tables), with
//     illuminant E normalised so that reflectance 1 gives Y = 1, then XYZ to
//     linear Rec.709 (sRGB primaries).
// A constant reflectance 1 has XYZ ~ (1, 1, 1) under E, whose Rec.709 value is
// not white but kEqualEnergyRgb ~ (1.20, 0.95, 0.91). thinFilmRgb offers both
// the plain conversion and a white-balanced one (divided by that, so that a
// grey spectrum is grey), the convention of the specification's m = 0 term.
#include <glm/vec3.hpp>

namespace vkrt::test {

/// One thin-film configuration. The base's F0 is that of base against air.
struct ThinFilm {
    double outsideIor = 1.0;
    double filmIor = 1.5;
    double thicknessNm = 300.0;
    double baseF0 = 0.04;
};

/// The visible range integrated over, in nanometres (inclusive, 1 nm steps).
inline constexpr int kFirstWavelengthNm = 380;
inline constexpr int kLastWavelengthNm = 780;

/// How a spectrum's XYZ becomes RGB.
enum class RgbWhite {
    EqualEnergy, ///< XYZ (illuminant E, Y of reflectance 1 = 1) to Rec.709 as is
    Balanced,    ///< the same, divided per channel by the RGB of reflectance 1: grey stays grey
};

/// The base's IOR from its F0 against air (infinity for F0 >= 1).
double baseIorFromF0(double baseF0);
/// Unpolarized reflectance of the stack at one wavelength, cosTheta in [0, 1]
/// the cosine of incidence in the outside medium. A film of thickness 0 gives
/// the outside/base interface's Fresnel reflectance exactly.
double thinFilmReflectance(const ThinFilm& film, double cosTheta, double wavelengthNm);
/// Unpolarized Fresnel reflectance of one dielectric interface n1 -> n2 (1 under total internal reflection).
double dielectricFresnel(double n1, double n2, double cosTheta);
/// The CIE 1931 2-degree colour-matching functions (Wyman, Sloan and Shirley's piecewise-Gaussian fit).
glm::dvec3 cieXyzMatching(double wavelengthNm);
/// The spectrum's XYZ (illuminant E, reflectance 1 gives Y = 1).
glm::dvec3 thinFilmXyz(const ThinFilm& film, double cosTheta);
/// XYZ to linear Rec.709.
glm::dvec3 xyzToLinearRec709(const glm::dvec3& xyz);
/// RGB of reflectance 1 under RgbWhite::EqualEnergy.
glm::dvec3 equalEnergyRgb();
/// The stack's reflectance as linear Rec.709.
glm::dvec3 thinFilmRgb(const ThinFilm& film, double cosTheta, RgbWhite white = RgbWhite::Balanced);

} // namespace vkrt::test
