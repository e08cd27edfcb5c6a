#include "material/Sheen.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <thread>
#include <vector>

namespace vkrt {

double sheenAlpha(double roughness) { return std::max(roughness * roughness, kMinSheenAlpha); }

double charlieDistribution(double cosH, double alpha)
{
    const double sin2h = std::max(1.0 - cosH * cosH, 0.0);
    return (2.0 + 1.0 / alpha) * std::pow(sin2h, 0.5 / alpha) / (2.0 * std::numbers::pi);
}

namespace {

double charlieL(double x, double alpha)
{
    const double t = (1.0 - alpha) * (1.0 - alpha);
    auto mix = [t](double a, double b) { return a + (b - a) * t; };
    const double a = mix(21.5473, 25.3245), b = mix(3.82987, 3.32435), c = mix(0.19823, 0.16801);
    const double d = mix(-1.97760, -1.27393), e = mix(-4.32054, -4.85967);
    return a / (1.0 + b * std::pow(x, c)) + d * x + e;
}

} // namespace

double charlieLambda(double cosTheta, double alpha)
{
    const double c = std::abs(cosTheta);
    return c < 0.5 ? std::exp(charlieL(c, alpha)) : std::exp(2.0 * charlieL(0.5, alpha) - charlieL(1.0 - c, alpha));
}

double sheenBrdf(double cosO, double cosI, double cosH, double alpha)
{
    return charlieDistribution(cosH, alpha) /
           ((1.0 + charlieLambda(cosO, alpha) + charlieLambda(cosI, alpha)) * 4.0 * cosO * cosI);
}

double sheenDirectionalAlbedo(double mu, double roughness)
{
    const double alpha = sheenAlpha(roughness);
    const double sinO = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    // cos(theta_i) = t^2 (dcos = 2t dt), phi over [0, pi] doubled (the lobe is symmetric about wo's plane).
    constexpr int kT = 64, kPhi = 32;
    // sheenBrdf(mu, cosI, cosH, alpha) term by term, with what does not
    // change along a loop taken out of it: the same operations on the same
    // values, so the same sum bit for bit (tests/material/sheen_table_test.cpp),
    // at a quarter of the cost (the table is part of a sheen scene's start-up).
    std::array<double, kPhi> cosPhi, sinPhi;
    for (int b = 0; b < kPhi; ++b) {
        const double phi = std::numbers::pi * (b + 0.5) / kPhi;
        cosPhi[b] = std::cos(phi);
        sinPhi[b] = std::sin(phi);
    }
    const double lambdaO = charlieLambda(mu, alpha);
    double sum = 0.0;
    for (int a = 0; a < kT; ++a) {
        const double t = (a + 0.5) / kT;
        const double cosI = t * t, sinI = std::sqrt(std::max(0.0, 1.0 - cosI * cosI));
        const double shadowing = (1.0 + lambdaO + charlieLambda(cosI, alpha)) * 4.0 * mu * cosI;
        double ring = 0.0;
        for (int b = 0; b < kPhi; ++b) {
            // h = normalize(wo + wi), wo = (sinO, 0, mu), wi = (sinI cos phi, sinI sin phi, cosI).
            const double hx = sinO + sinI * cosPhi[b], hy = sinI * sinPhi[b], hz = mu + cosI;
            const double cosH = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
            ring += charlieDistribution(cosH, alpha) / shadowing;
        }
        sum += ring * cosI * 2.0 * t;
    }
    return sum * (1.0 / kT) * (2.0 * std::numbers::pi / kPhi);
}

const std::vector<float>& sheenAlbedoTable()
{
    static const std::vector<float> table = [] {
        constexpr uint32_t side = kSheenTableSide;
        std::vector<float> entries(size_t(side) * side);
        // 8 million BRDF values: 0.25 s of a sheen scene's start-up on one
        // core, so the rows are shared among the cores (each entry is
        // computed alone: the table is the same for any number of threads).
        std::atomic<uint32_t> nextRow{0};
        auto work = [&] {
            for (uint32_t j; (j = nextRow++) < side;)
                for (uint32_t i = 0; i < side; ++i) {
                    const double s = double(i) / (side - 1);
                    const double mu = std::max(s * s, 1e-4);
                    entries[size_t(j) * side + i] = float(sheenDirectionalAlbedo(mu, double(j) / (side - 1)));
                }
        };
        std::vector<std::thread> threads;
        for (unsigned t = 1; t < std::max(1u, std::thread::hardware_concurrency()); ++t) threads.emplace_back(work);
        work();
        for (std::thread& thread : threads) thread.join();
        return entries;
    }();
    return table;
}

} // namespace vkrt
