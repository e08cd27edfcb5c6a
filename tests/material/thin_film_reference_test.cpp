// The spectral thin-film reference (support/ThinFilmReference.h) checked
// against what optics says it must reduce to: a vanishing film, films that
// match the medium on one side, energy bounds, the textbook quarter-wave
// coating, and the colour-matching fit's known values.
#include "support/ThinFilmReference.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vkrt::test {
namespace {

constexpr double kCosines[] = {1.0, 0.8, 0.5, 0.2, 0.05};
constexpr double kWavelengths[] = {380.0, 450.0, 550.0, 633.0, 780.0};

/// The F0 against air of a dielectric of IOR n.
double f0OfIor(double n)
{
    double r = (n - 1.0) / (n + 1.0);
    return r * r;
}

TEST(ThinFilmReference, AVanishingFilmLeavesThePlainInterface)
{
    for (double outside : {1.0, 1.5})
        for (double filmIor : {1.2, 2.0})
            for (double c : kCosines)
                for (double nm : kWavelengths) {
                    ThinFilm film{outside, filmIor, 0.0, 0.1};
                    if (outside > filmIor && (1.0 - c * c) * (outside / filmIor) * (outside / filmIor) >= 1.0)
                        continue; // a 1e-4 nm film still carries TIR's evanescent wave differently
                    double plain = dielectricFresnel(outside, baseIorFromF0(film.baseF0), c);
                    EXPECT_EQ(thinFilmReflectance(film, c, nm), plain);
                    film.thicknessNm = 1e-4; // phase 4 pi n d cos / lambda ~ 1e-5
                    EXPECT_NEAR(thinFilmReflectance(film, c, nm), plain, 1e-5) << outside << " " << filmIor << " " << c;
                }
}

TEST(ThinFilmReference, AFilmMatchingTheOutsideIsInvisible)
{
    for (double outside : {1.0, 1.5})
        for (double thickness : {50.0, 333.0, 1200.0})
            for (double c : kCosines)
                for (double nm : kWavelengths) {
                    ThinFilm film{outside, outside, thickness, 0.2};
                    EXPECT_NEAR(thinFilmReflectance(film, c, nm), dielectricFresnel(outside, baseIorFromF0(0.2), c),
                                1e-12);
                }
}

TEST(ThinFilmReference, AFilmMatchingTheBaseIsTheTopInterface)
{
    for (double outside : {1.0, 1.5})
        for (double filmIor : {1.3, 1.8})
            for (double c : kCosines)
                for (double nm : kWavelengths) {
                    ThinFilm film{outside, filmIor, 417.0, f0OfIor(filmIor)};
                    EXPECT_NEAR(thinFilmReflectance(film, c, nm), dielectricFresnel(outside, filmIor, c), 1e-12);
                }
}

TEST(ThinFilmReference, ReflectanceStaysWithinZeroAndOne)
{
    for (double outside : {1.0, 1.5})
        for (double filmIor : {1.0, 1.2, 1.5, 2.0, 3.0})
            for (double f0 : {0.0, 0.04, 0.5, 0.9, 1.0})
                for (double thickness : {0.0, 1.0, 90.0, 600.0, 1200.0})
                    for (double c : {1.0, 0.7, 0.3, 0.1, 0.0})
                        for (double nm : kWavelengths) {
                            double r = thinFilmReflectance({outside, filmIor, thickness, f0}, c, nm);
                            ASSERT_TRUE(r >= 0.0 && r <= 1.0 + 1e-12) << r << " at " << outside << " " << filmIor << " "
                                                                      << f0 << " " << thickness << " " << c;
                        }
}

TEST(ThinFilmReference, APerfectMirrorUnderALosslessFilmReflectsEverything)
{
    for (double thickness : {0.0, 120.0, 1000.0})
        for (double c : kCosines)
            for (double nm : kWavelengths)
                EXPECT_NEAR(thinFilmReflectance({1.0, 1.7, thickness, 1.0}, c, nm), 1.0, 1e-12);
}

// A quarter-wave film (n2 d = lambda / 4) at normal incidence reflects
// ((n1 n3 - n2^2) / (n1 n3 + n2^2))^2 at lambda: the minimum of an
// anti-reflection coating when n2 lies between n1 and n3, a maximum when the
// film is denser than both.
TEST(ThinFilmReference, AQuarterWaveFilmGivesTheTextbookExtremum)
{
    const double n1 = 1.0, n3 = 1.52, lambda = 550.0;
    for (double n2 : {1.38, 2.3}) {
        ThinFilm film{n1, n2, lambda / (4.0 * n2), f0OfIor(n3)};
        double expected = std::pow((n1 * n3 - n2 * n2) / (n1 * n3 + n2 * n2), 2.0);
        double atLambda = thinFilmReflectance(film, 1.0, lambda);
        EXPECT_NEAR(atLambda, expected, 1e-12) << n2;
        for (double offset : {-30.0, 30.0}) {
            double beside = thinFilmReflectance(film, 1.0, lambda + offset);
            if (n2 < n3) EXPECT_GT(beside, atLambda) << n2; // a minimum
            else EXPECT_LT(beside, atLambda) << n2;         // a maximum
        }
    }
    EXPECT_LT(std::pow((n1 * n3 - 1.38 * 1.38) / (n1 * n3 + 1.38 * 1.38), 2.0), f0OfIor(n3)); // it does coat
}

TEST(ThinFilmReference, ColourMatchingFitHasTheCieValues)
{
    // CIE 1931 2-degree table values; the fit's stated accuracy is a few per cent of the peak.
    EXPECT_NEAR(cieXyzMatching(555.0).y, 1.0000, 0.02);
    EXPECT_NEAR(cieXyzMatching(600.0).x, 1.0622, 0.03);
    EXPECT_NEAR(cieXyzMatching(445.0).z, 1.7826, 0.06);
    EXPECT_NEAR(cieXyzMatching(500.0).x, 0.0049, 0.03);
    // Equal-energy white: X, Y and Z integrate to nearly the same value, and
    // its Rec.709 colour is not (1, 1, 1) (sRGB's white is D65).
    glm::dvec3 e = equalEnergyRgb();
    EXPECT_NEAR(e.r, 1.20, 0.02);
    EXPECT_NEAR(e.g, 0.95, 0.02);
    EXPECT_NEAR(e.b, 0.91, 0.02);
}

TEST(ThinFilmReference, ConstantReflectanceIntegratesToItsValue)
{
    // A perfect mirror under a film reflects 1 at every wavelength: Y = 1, and grey balanced RGB.
    ThinFilm mirror{1.0, 1.6, 250.0, 1.0};
    EXPECT_NEAR(thinFilmXyz(mirror, 0.6).y, 1.0, 1e-12);
    glm::dvec3 balanced = thinFilmRgb(mirror, 0.6, RgbWhite::Balanced);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(balanced[k], 1.0, 1e-12);
    glm::dvec3 plain = thinFilmRgb(mirror, 0.6, RgbWhite::EqualEnergy);
    EXPECT_NEAR(plain.r, equalEnergyRgb().r, 1e-12);
    // A coloured film is not grey.
    glm::dvec3 film = thinFilmRgb({1.0, 2.0, 300.0, 0.04}, 1.0);
    EXPECT_GT(std::abs(film.r - film.b), 0.01);
}

} // namespace
} // namespace vkrt::test
