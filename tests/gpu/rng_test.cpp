// The render kernels' random numbers (shaders/lib/random.glsl): every draw is
// pcg4d(pixelIndex, frameIndex, seed, dimension), 24 high bits per lane.
//
// No two (pixel, frame) pairs share a sample, by construction: for a fixed seed
// and dimension the input uvec4(pixel, frame, seed, dimension) differs between
// any two distinct pairs (pixel < 2^18 and frame < 2^10 each have a lane of their
// own, nothing is packed or added), and pcg4d is a bijection of uvec4, since each
// of its steps is invertible:
//   v = v * 1664525 + 1013904223   an odd multiplier is a unit mod 2^32,
//   v.x += v.y * v.w  (etc.)       given the other lanes, subtract the same term,
//   v ^= v >> 16                   its own inverse on 32 bits.
// So the outputs of the 512 x 512 x 1024 pairs are pairwise distinct. The tests
// below check this: a C++ pcg4d and its inverse (inverse(pcg4d(v)) == v for
// 1e6 random v and for every pair of the grid), the GPU's pcg4d equal to the C++
// one, and the statistics of the draws along frames and across pixels.
#include "support/ProbeKernel.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

// ---------------------------------------------------------------------------
// pcg4d and its inverse

using U4 = std::array<uint32_t, 4>;

constexpr uint32_t kMultiplier = 1664525u;
constexpr uint32_t kIncrement = 1013904223u;

/// Multiplicative inverse of an odd number mod 2^32 by Newton's iteration
/// x <- x (2 - a x), which doubles the number of correct low bits (a * a = 1 mod 8).
constexpr uint32_t inverseOdd(uint32_t a)
{
    uint32_t x = a;
    for (int i = 0; i < 5; ++i) x *= 2u - a * x;
    return x;
}
constexpr uint32_t kMultiplierInverse = inverseOdd(kMultiplier);
static_assert(kMultiplier * kMultiplierInverse == 1u);

U4 pcg4d(U4 v) { return pcg4dReference(v); }

/// Undoes the four lane updates: the last one first, each given the other lanes.
void unmix(U4& v)
{
    v[3] -= v[1] * v[2];
    v[2] -= v[0] * v[1];
    v[1] -= v[2] * v[0];
    v[0] -= v[1] * v[3];
}

U4 pcg4dInverse(U4 v)
{
    unmix(v);
    for (uint32_t& x : v) x ^= x >> 16u; // an involution on 32 bits
    unmix(v);
    for (uint32_t& x : v) x = (x - kIncrement) * kMultiplierInverse;
    return v;
}

std::string hex(const U4& v)
{
    std::ostringstream text;
    text << std::hex << "(" << v[0] << ", " << v[1] << ", " << v[2] << ", " << v[3] << ")";
    return text.str();
}

/// Values that exercise carries and the xorshift: zero, all ones, single bits.
std::vector<U4> specialInputs()
{
    std::vector<U4> inputs;
    const std::array<uint32_t, 8> values = {0u,          1u,          0xffffffffu, 0x80000000u,
                                            0x7fffffffu, 0x0000ffffu, 0xffff0000u, 0x10000u};
    for (uint32_t a : values)
        for (uint32_t b : values) inputs.push_back({a, b, a ^ b, b});
    return inputs;
}

class RngProbe : public GpuTest {};

TEST(RngProbeCpu, Pcg4dInverseRoundTrips)
{
    std::mt19937 rng(2718u);
    int64_t failures = 0;
    for (int i = 0; i < 1000000; ++i) {
        U4 v = {uint32_t(rng()), uint32_t(rng()), uint32_t(rng()), uint32_t(rng())};
        if (pcg4dInverse(pcg4d(v)) != v || pcg4d(pcg4dInverse(v)) != v) {
            if (failures++ < 5) ADD_FAILURE() << "round trip fails for " << hex(v);
        }
    }
    for (const U4& v : specialInputs()) EXPECT_EQ(pcg4dInverse(pcg4d(v)), v) << hex(v);
    EXPECT_EQ(failures, 0);
    // The inverse is not vacuous: it does not map pcg4d(v) to v for a slightly
    // different hash (the second mixing round without its last step).
    U4 v = {1u, 2u, 3u, 4u};
    U4 h = pcg4d(v);
    h[3] -= h[1] * h[2];
    EXPECT_NE(pcg4dInverse(h), v);
}

// Every (pixel, frame) of a 512 x 512 image over 1024 frames (2^28 pairs), run on
// the GPU with the real pcg4d: each output maps back through the inverse to its own
// input, so no two pairs can share an output (a collision would map back to a single
// input for both). The per-pixel checksums of the GPU's outputs match the C++ pcg4d
// on a sample of pixels, so the GPU really evaluated pcg4d.
TEST_F(RngProbe, NoSeedCollisionsOverPixelsAndFrames)
{
    constexpr uint32_t kPixels = 512u * 512u, kFrames = 1024u;
    for (uint32_t dimension : {0u, 3u}) {
        const uint32_t seed = dimension == 0u ? 0u : 12345u;
        std::vector<float> input = {float(kFrames), float(seed), float(dimension), float(kMultiplierInverse & 0xffffu),
                                    float(kMultiplierInverse >> 16u)};
        std::vector<float> out = runProbe("pcg_grid_probe", input, 3 * size_t(kPixels), kPixels);
        int64_t mismatches = 0, badChecksums = 0;
        for (uint32_t pixel = 0; pixel < kPixels; ++pixel) mismatches += int64_t(out[3 * pixel]);
        for (uint32_t pixel = 0; pixel < kPixels; pixel += 97) {
            uint32_t checksum = 0;
            for (uint32_t frame = 0; frame < kFrames; ++frame) {
                U4 h = pcg4d({pixel, frame, seed, dimension});
                checksum ^= h[0] ^ h[1] ^ h[2] ^ h[3];
            }
            uint32_t gpu = uint32_t(out[3 * pixel + 1]) | (uint32_t(out[3 * pixel + 2]) << 16u);
            if (gpu != checksum && badChecksums++ < 5)
                ADD_FAILURE() << "pixel " << pixel << ": GPU checksum " << gpu << ", C++ " << checksum;
        }
        EXPECT_EQ(mismatches, 0) << "dimension " << dimension;
        EXPECT_EQ(badChecksums, 0) << "dimension " << dimension;
        reportStat("PairsChecked_dimension" + std::to_string(dimension), double(kPixels) * kFrames);
        reportStat("Collisions_dimension" + std::to_string(dimension), double(mismatches));
    }
}

// The grid check can fail: a hash that drops information (here the frame's top
// bit) maps two pairs to one output, and the inverse cannot return both inputs.
TEST(RngProbeCpu, InverseCheckDetectsACollidingHash)
{
    int64_t mismatches = 0;
    for (uint32_t pixel = 0; pixel < 64; ++pixel)
        for (uint32_t frame = 0; frame < 1024; ++frame) {
            U4 v = {pixel, frame, 0u, 0u};
            U4 h = pcg4d({pixel, frame & 511u, 0u, 0u});
            if (pcg4dInverse(h) != v) ++mismatches;
        }
    EXPECT_EQ(mismatches, 64 * 512);
}

// ---------------------------------------------------------------------------
// The GPU's pcg4d against the C++ one

std::vector<U4> gpuPcg4d(const std::vector<U4>& inputs)
{
    std::vector<float> input;
    input.reserve(8 * inputs.size());
    for (const U4& v : inputs)
        for (uint32_t x : v) input.insert(input.end(), {float(x & 0xffffu), float(x >> 16u)});
    std::vector<float> out = runProbe("pcg_probe", input, 8 * inputs.size(), uint32_t(inputs.size()));
    std::vector<U4> result(inputs.size());
    for (size_t i = 0; i < inputs.size(); ++i)
        for (int k = 0; k < 4; ++k)
            result[i][k] = uint32_t(out[8 * i + 2 * k]) | (uint32_t(out[8 * i + 2 * k + 1]) << 16u);
    return result;
}

TEST_F(RngProbe, GpuPcg4dMatchesCpu)
{
    std::vector<U4> inputs = specialInputs();
    std::mt19937 rng(1618u);
    for (int i = 0; i < 200000; ++i)
        inputs.push_back({uint32_t(rng()), uint32_t(rng()), uint32_t(rng()), uint32_t(rng())});
    // Corners and random points of the (pixel, frame, seed, dimension) grid.
    for (uint32_t pixel : {0u, 1u, 511u, 512u, 262143u})
        for (uint32_t frame : {0u, 1u, 1023u})
            for (uint32_t dimension : {0u, 1u, 2u}) inputs.push_back({pixel, frame, 0u, dimension});
    for (int i = 0; i < 50000; ++i)
        inputs.push_back({uint32_t(rng() % 262144u), uint32_t(rng() % 1024u), 7u, uint32_t(rng() % 8u)});
    std::vector<U4> gpu = gpuPcg4d(inputs);
    int64_t mismatches = 0;
    for (size_t i = 0; i < inputs.size(); ++i)
        if (gpu[i] != pcg4d(inputs[i]) && mismatches++ < 5)
            ADD_FAILURE() << "pcg4d" << hex(inputs[i]) << ": GPU " << hex(gpu[i]) << ", C++ " << hex(pcg4d(inputs[i]));
    EXPECT_EQ(mismatches, 0) << "of " << inputs.size();
    reportStat("Pcg4dInputsCompared", double(inputs.size()));
}

// ---------------------------------------------------------------------------
// Statistics of the draws

constexpr uint32_t kImageWidth = 512;
constexpr uint32_t kTileX = 100, kTileY = 200, kTileWidth = 32, kTileHeight = 32, kFrames = 1024, kSeed = 7;

/// First two sampleNext4D draws (8 numbers) of each pixel of the tile in each frame.
struct Draws {
    std::vector<float> values; ///< [(tilePixel * kFrames + frame) * 8 + k]
    float at(uint32_t col, uint32_t row, uint32_t frame, uint32_t k) const
    {
        return values[((size_t(row) * kTileWidth + col) * kFrames + frame) * 8 + k];
    }
};

uint32_t pixelIndexOf(uint32_t col, uint32_t row) { return (kTileY + row) * kImageWidth + kTileX + col; }

float toUnitFloat(uint32_t bits) { return float(bits >> 8u) * (1.0f / 16777216.0f); }

using Hash = std::function<U4(uint32_t pixel, uint32_t frame, uint32_t seed, uint32_t dimension)>;

/// The draws a sampler built on `hash` would give (random.glsl's layout for pcg4d).
Draws cpuDraws(const Hash& hash)
{
    Draws d;
    d.values.resize(size_t(kTileWidth) * kTileHeight * kFrames * 8);
    for (uint32_t row = 0; row < kTileHeight; ++row)
        for (uint32_t col = 0; col < kTileWidth; ++col)
            for (uint32_t frame = 0; frame < kFrames; ++frame)
                for (uint32_t dimension = 0; dimension < 2; ++dimension) {
                    U4 bits = hash(pixelIndexOf(col, row), frame, kSeed, dimension);
                    for (int k = 0; k < 4; ++k)
                        d.values[((size_t(row) * kTileWidth + col) * kFrames + frame) * 8 + 4 * dimension + k] =
                            toUnitFloat(bits[k]);
                }
    return d;
}

U4 renderHash(uint32_t pixel, uint32_t frame, uint32_t seed, uint32_t dimension)
{
    return pcg4d({pixel, frame, seed, dimension});
}

const Draws& gpuDraws()
{
    static const Draws draws = [] {
        std::vector<float> input = {float(kImageWidth), float(kTileX),  float(kTileY), float(kTileWidth),
                                    float(kTileHeight), float(kFrames), float(kSeed)};
        uint32_t invocations = kTileWidth * kTileHeight * kFrames;
        Draws d;
        d.values = runProbe("rng_stats_probe", input, size_t(invocations) * 8, invocations);
        return d;
    }();
    return draws;
}

struct Correlation {
    std::string name;
    double r = 0.0;
    int64_t n = 0;
    double bound() const { return 4.0 / std::sqrt(double(n)); }
    bool ok() const { return std::abs(r) < bound(); }
};

/// Pearson correlation of the pairs (a(i), b(i)) that `pairs` enumerates.
Correlation pearson(const std::string& name,
                    const std::function<void(const std::function<void(double, double)>&)>& pairs)
{
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    int64_t n = 0;
    pairs([&](double x, double y) {
        sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y;
        ++n;
    });
    double mx = sx / n, my = sy / n;
    double cov = sxy / n - mx * my, vx = sxx / n - mx * mx, vy = syy / n - my * my;
    return {name, cov / std::sqrt(vx * vy), n};
}

std::vector<Correlation> correlations(const Draws& d)
{
    std::vector<Correlation> result;
    // The first random number of a pixel, frame f against f + 1 (lag 1 along frames).
    result.push_back(pearson("first number, frame f vs f+1", [&](const auto& add) {
        for (uint32_t row = 0; row < kTileHeight; ++row)
            for (uint32_t col = 0; col < kTileWidth; ++col)
                for (uint32_t f = 0; f + 1 < kFrames; ++f) add(d.at(col, row, f, 0), d.at(col, row, f + 1, 0));
    }));
    // Neighbouring pixels in the same frame: horizontal (pixel index + 1) and vertical (+ width).
    result.push_back(pearson("first number, pixel vs right neighbour", [&](const auto& add) {
        for (uint32_t row = 0; row < kTileHeight; ++row)
            for (uint32_t col = 0; col + 1 < kTileWidth; ++col)
                for (uint32_t f = 0; f < kFrames; ++f) add(d.at(col, row, f, 0), d.at(col + 1, row, f, 0));
    }));
    result.push_back(pearson("first number, pixel vs lower neighbour", [&](const auto& add) {
        for (uint32_t row = 0; row + 1 < kTileHeight; ++row)
            for (uint32_t col = 0; col < kTileWidth; ++col)
                for (uint32_t f = 0; f < kFrames; ++f) add(d.at(col, row, f, 0), d.at(col, row + 1, f, 0));
    }));
    // Diagonal in (pixel, frame): the signature of seeding with pixel + frame.
    result.push_back(pearson("first number, (pixel+1, f) vs (pixel, f+1)", [&](const auto& add) {
        for (uint32_t row = 0; row < kTileHeight; ++row)
            for (uint32_t col = 0; col + 1 < kTileWidth; ++col)
                for (uint32_t f = 0; f + 1 < kFrames; ++f) add(d.at(col + 1, row, f, 0), d.at(col, row, f + 1, 0));
    }));
    // Every number of the sample vector (dimensions 0 and 1, lanes x..w), frame f vs f + 1.
    for (uint32_t k = 0; k < 8; ++k)
        result.push_back(pearson("number " + std::to_string(k) + ", frame f vs f+1", [&](const auto& add) {
            for (uint32_t row = 0; row < kTileHeight; ++row)
                for (uint32_t col = 0; col < kTileWidth; ++col)
                    for (uint32_t f = 0; f + 1 < kFrames; ++f) add(d.at(col, row, f, k), d.at(col, row, f + 1, k));
        }));
    // Within one sample: consecutive lanes, and the same lane of consecutive dimensions.
    for (uint32_t k = 0; k < 7; ++k)
        result.push_back(pearson("number " + std::to_string(k) + " vs " + std::to_string(k + 1) + ", same sample",
                                 [&](const auto& add) {
                                     for (size_t i = 0; i < d.values.size(); i += 8)
                                         add(d.values[i + k], d.values[i + k + 1]);
                                 }));
    result.push_back(pearson("dimension 0 vs 1, lane x", [&](const auto& add) {
        for (size_t i = 0; i < d.values.size(); i += 8) add(d.values[i], d.values[i + 4]);
    }));
    return result;
}

int failedCorrelations(const Draws& d, bool print)
{
    int failed = 0;
    for (const Correlation& c : correlations(d)) {
        if (!c.ok()) ++failed;
        if (print)
            std::cout << "[   STAT   ] " << std::setw(46) << std::left << c.name << std::right
                      << " r = " << std::setw(12) << c.r << "  bound " << c.bound() << "  N " << c.n << std::endl;
    }
    return failed;
}

TEST_F(RngProbe, GpuSamplerDrawsAreTheHashOfPixelFrameSeedDimension)
{
    const Draws& gpu = gpuDraws();
    Draws cpu = cpuDraws(renderHash);
    ASSERT_EQ(gpu.values.size(), cpu.values.size());
    int64_t mismatches = 0;
    for (size_t i = 0; i < cpu.values.size(); ++i)
        if (gpu.values[i] != cpu.values[i] && mismatches++ < 5)
            ADD_FAILURE() << "draw " << i << ": GPU " << gpu.values[i] << ", expected " << cpu.values[i];
    EXPECT_EQ(mismatches, 0) << "of " << cpu.values.size();
}

TEST_F(RngProbe, DrawsAreUncorrelatedAlongFramesAndAcrossPixels)
{
    const Draws& gpu = gpuDraws();
    std::vector<Correlation> all = correlations(gpu);
    for (const Correlation& c : all) {
        EXPECT_LT(std::abs(c.r), c.bound()) << c.name << " over " << c.n << " pairs";
        EXPECT_GE(c.n, 1000000) << c.name;
    }
    failedCorrelations(gpu, true);
    reportStat("FrameLag1Correlation", all[0].r);
    reportStat("RightNeighbourCorrelation", all[1].r);
    reportStat("LowerNeighbourCorrelation", all[2].r);
    reportStat("CorrelationBound", all[0].bound());
}

TEST_F(RngProbe, UniformDrawsHaveMeanOneHalfAndVarianceOneTwelfth)
{
    const Draws& gpu = gpuDraws();
    // All 8.4e6 numbers together, and each of the 8 numbers of a sample on its own.
    for (int lane = -1; lane < 8; ++lane) {
        double sum = 0.0, sumSq = 0.0, lo = 1.0, hi = 0.0;
        int64_t n = 0;
        for (size_t i = 0; i < gpu.values.size(); ++i) {
            if (lane >= 0 && int(i % 8) != lane) continue;
            double x = gpu.values[i];
            sum += x, sumSq += x * x, ++n;
            lo = std::min(lo, x), hi = std::max(hi, x);
        }
        double mean = sum / n, variance = sumSq / n - mean * mean;
        // Standard errors: sqrt(sigma^2 / n) for the mean, sqrt((mu4 - sigma^4) / n) with
        // mu4 = 1/80 and sigma^4 = 1/144 for the variance of a uniform variable.
        double meanError = std::sqrt(1.0 / 12.0 / n), varianceError = std::sqrt((1.0 / 80.0 - 1.0 / 144.0) / n);
        std::string what = lane < 0 ? "all numbers" : "number " + std::to_string(lane);
        EXPECT_LT(std::abs(mean - 0.5), 4.0 * meanError) << what << ": mean " << mean;
        EXPECT_LT(std::abs(variance - 1.0 / 12.0), 4.0 * varianceError) << what << ": variance " << variance;
        EXPECT_GE(lo, 0.0) << what;
        EXPECT_LT(hi, 1.0) << what;
        EXPECT_GE(n, 1000000);
        if (lane < 0) {
            reportStat("Count", double(n));
            reportStat("MeanMinusHalf", mean - 0.5);
            reportStat("MeanStandardError", meanError);
            reportStat("VarianceMinusTwelfth", variance - 1.0 / 12.0);
            reportStat("VarianceStandardError", varianceError);
        }
    }
}

// The correlation checks reject samplers with the classic seeding mistakes, so
// they can fail: the frame left out of the hash, seeding with pixel + frame, and a
// plain per-lane LCG without pcg4d's mixing.
TEST(RngProbeCpu, CorrelationChecksRejectBadSeeding)
{
    EXPECT_EQ(failedCorrelations(cpuDraws(renderHash), false), 0);
    Draws noFrame = cpuDraws([](uint32_t pixel, uint32_t, uint32_t seed, uint32_t dim) {
        return pcg4d({pixel, 0u, seed, dim});
    });
    Draws pixelPlusFrame = cpuDraws([](uint32_t pixel, uint32_t frame, uint32_t seed, uint32_t dim) {
        return pcg4d({pixel + frame, 0u, seed, dim});
    });
    Draws lcgOnly = cpuDraws([](uint32_t pixel, uint32_t frame, uint32_t seed, uint32_t dim) {
        U4 v = {pixel, frame, seed, dim};
        for (uint32_t& x : v) x = x * kMultiplier + kIncrement;
        return v;
    });
    std::vector<Correlation> a = correlations(noFrame), b = correlations(pixelPlusFrame), c = correlations(lcgOnly);
    EXPECT_FALSE(a[0].ok()) << "frame lag-1 with the frame left out: r = " << a[0].r;
    EXPECT_FALSE(b[3].ok()) << "diagonal with pixel + frame seeding: r = " << b[3].r;
    EXPECT_FALSE(c[1].ok()) << "right neighbour with a plain LCG: r = " << c[1].r;
    reportStat("NoFrameLag1", a[0].r);
    reportStat("PixelPlusFrameDiagonal", b[3].r);
    reportStat("LcgRightNeighbour", c[1].r);
}

} // namespace
} // namespace vkrt::test
