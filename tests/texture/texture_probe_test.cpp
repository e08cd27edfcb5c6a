// lib/texture.glsl on the test GPU (tests/gpu/kernels/texture_probe.comp)
// against a double-precision CPU reference of the same rules, written here
// independently: uv convention, wrap modes on texel indices, bilinear within a
// level, linear between levels, sRGB decoding per texel before filtering,
// and the records' filters (nearest texels, the nearest level, level 0 alone).
#include "support/ProbeBuffers.h"
#include "support/TestSupport.h"
#include "texture/TextureAtlas.h"

#include <Imath/half.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace vkrt::test {
namespace {

using Rgba = std::array<double, 4>;

double srgbReference(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

/// The CPU reference of sampleTexture over packed buffers. `flipV = false`
/// gives a deliberately wrong convention, to show the comparison can fail.
class ReferenceSampler {
public:
    explicit ReferenceSampler(const TextureBuffers& buffers, bool flipV = true) : m_buffers(buffers), m_flipV(flipV) {}

    /// `lod` is a float, as the kernel's: the levels it picks are rounded as the kernel rounds.
    Rgba sample(uint32_t texture, double u, double v, float lod) const
    {
        const gpu::TextureRecord& record = m_buffers.records[texture];
        const uint32_t filters = record.filters;
        if (!(lod > 0.0f)) return filtered(record, 0, u, v, filters & gpu::TEXTURE_FILTER_MAG_NEAREST);
        const bool nearest = filters & gpu::TEXTURE_FILTER_MIN_NEAREST;
        if (filters & gpu::TEXTURE_FILTER_MIP_NONE) return filtered(record, 0, u, v, nearest);
        lod = std::min(lod, float(record.levels - 1));
        if (filters & gpu::TEXTURE_FILTER_MIP_NEAREST)
            return filtered(record, uint32_t(std::floor(lod + 0.5f)), u, v, nearest);
        const double level = std::floor(lod), t = lod - level;
        const Rgba fine = filtered(record, uint32_t(level), u, v, nearest);
        if (t == 0.0) return fine;
        const Rgba coarse = filtered(record, uint32_t(level) + 1, u, v, nearest);
        Rgba out;
        for (int c = 0; c < 4; ++c) out[c] = fine[c] * (1.0 - t) + coarse[c] * t;
        return out;
    }

private:
    static int64_t wrap(int64_t i, int64_t n, uint32_t mode)
    {
        if (mode == gpu::TEXTURE_WRAP_CLAMP) return std::clamp<int64_t>(i, 0, n - 1);
        if (mode == gpu::TEXTURE_WRAP_REPEAT) return ((i % n) + n) % n;
        const int64_t j = ((i % (2 * n)) + 2 * n) % (2 * n);
        return j < n ? j : 2 * n - 1 - j;
    }

    Rgba texel(const gpu::TextureRecord& record, uint32_t level, int64_t x, int64_t y) const
    {
        const int64_t width = std::max(1u, record.width >> level);
        const size_t index = size_t(y * width + x);
        const uint32_t offset = record.levelOffset[level];
        Rgba out;
        if (record.format == gpu::TEXTURE_FORMAT_RGBA16F) {
            for (int c = 0; c < 4; ++c) {
                Imath::half h;
                h.setBits(uint16_t(m_buffers.texels[offset + 2 * index + c / 2] >> (16 * (c % 2))));
                out[c] = double(float(h));
            }
            return out;
        }
        const uint32_t word = m_buffers.texels[offset + index];
        for (int c = 0; c < 4; ++c) {
            const double value = ((word >> (8 * c)) & 0xffu) / 255.0;
            out[c] = record.format == gpu::TEXTURE_FORMAT_RGBA8_SRGB && c < 3 ? srgbReference(value) : value;
        }
        return out;
    }

    Rgba filtered(const gpu::TextureRecord& record, uint32_t level, double u, double v, bool nearest) const
    {
        return nearest ? nearestTexel(record, level, u, v) : bilinear(record, level, u, v);
    }

    /// The texel whose square holds (u, v). In float, as the kernel computes
    /// it: the nearest texel jumps at texel edges, where double arithmetic
    /// could round to the other side.
    Rgba nearestTexel(const gpu::TextureRecord& record, uint32_t level, double u, double v) const
    {
        const int64_t w = std::max(1u, record.width >> level), h = std::max(1u, record.height >> level);
        auto whole = [](float s, uint32_t mode) { // whole periods off, as wrapTextureCoordinate
            if (mode == gpu::TEXTURE_WRAP_REPEAT) return s - std::floor(s);
            if (mode == gpu::TEXTURE_WRAP_MIRROR) return s - 2.0f * std::floor(0.5f * s);
            return std::clamp(s, -1.0f, 2.0f);
        };
        const float s = whole(float(u), record.wrapU), t = whole(1.0f - float(v), record.wrapV);
        const auto x = int64_t(std::floor(s * float(w))), y = int64_t(std::floor(t * float(h)));
        return texel(record, level, wrap(x, w, record.wrapU), wrap(y, h, record.wrapV));
    }

    Rgba bilinear(const gpu::TextureRecord& record, uint32_t level, double u, double v) const
    {
        const int64_t w = std::max(1u, record.width >> level), h = std::max(1u, record.height >> level);
        // Texel centres at integers; y counts rows down from the file's top row.
        const double s = u * double(w) - 0.5, t = (m_flipV ? 1.0 - v : v) * double(h) - 0.5;
        const double x0 = std::floor(s), y0 = std::floor(t), fx = s - x0, fy = t - y0;
        Rgba out{};
        for (int dy = 0; dy < 2; ++dy) {
            for (int dx = 0; dx < 2; ++dx) {
                const double weight = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
                const Rgba value = texel(record, level, wrap(int64_t(x0) + dx, w, record.wrapU),
                                         wrap(int64_t(y0) + dy, h, record.wrapV));
                for (int c = 0; c < 4; ++c) out[c] += weight * value[c];
            }
        }
        return out;
    }

    const TextureBuffers& m_buffers;
    bool m_flipV;
};

struct Lookup {
    uint32_t texture;
    float u, v, lod;
};

std::vector<Rgba> sampleOnGpu(const TextureBuffers& buffers, const std::vector<Lookup>& lookups)
{
    std::vector<float> input;
    for (const Lookup& l : lookups) input.insert(input.end(), {0.0f, float(l.texture), l.u, l.v, l.lod});
    const std::vector<float> output =
        runProbeWithBuffers("texture_probe", input, lookups.size() * 4, uint32_t(lookups.size()),
                            {{gpu::BINDING_TEXTURE_TEXELS, probeBytes(buffers.texels)},
                             {gpu::BINDING_TEXTURE_RECORDS, probeBytes(buffers.records)}});
    std::vector<Rgba> results(lookups.size());
    for (size_t i = 0; i < lookups.size(); ++i)
        for (int c = 0; c < 4; ++c) results[i][c] = output[i * 4 + c];
    return results;
}

TextureImage randomImage(uint32_t width, uint32_t height, TexelEncoding encoding, std::mt19937& random, float lo,
                         float hi)
{
    std::uniform_real_distribution<float> value(lo, hi);
    TextureImage image{RgbaImage(width, height), encoding};
    for (float& x : image.pixels.rgba) x = value(random);
    return image;
}

class TextureProbe : public GpuTest {
protected:
    void SetUp() override
    {
        GpuTest::SetUp();
        std::mt19937 random(16);
        using W = TextureWrap;
        m_atlas.add(randomImage(5, 3, TexelEncoding::Srgb8, random, 0, 1), "a", W::Repeat, W::Clamp);
        m_atlas.add(randomImage(7, 4, TexelEncoding::Half, random, -1, 4), "b", W::Mirror, W::Repeat);
        m_atlas.add(randomImage(8, 6, TexelEncoding::Unorm8, random, 0, 1), "c", W::Clamp, W::Mirror);
        m_atlas.add(randomImage(13, 1, TexelEncoding::Srgb8, random, 0, 1), "d", W::Mirror, W::Mirror);
        m_atlas.add(randomImage(1, 1, TexelEncoding::Half, random, 0, 1), "e", W::Repeat, W::Repeat);
        m_atlas.add(randomImage(16, 16, TexelEncoding::Srgb8, random, 0, 1), "f", W::Repeat, W::Repeat);
        // Every filter of glTF's (records 6 to 11): nearest magnification,
        // nearest within levels, the nearest level, level 0 alone.
        using M = TextureFilter::Mip;
        m_atlas.add(randomImage(16, 16, TexelEncoding::Srgb8, random, 0, 1), "g", W::Repeat, W::Mirror, {true});
        m_atlas.add(randomImage(7, 4, TexelEncoding::Half, random, -1, 4), "h", W::Mirror, W::Repeat,
                    {false, true, M::Linear});
        m_atlas.add(randomImage(8, 6, TexelEncoding::Unorm8, random, 0, 1), "i", W::Clamp, W::Mirror,
                    {false, false, M::Nearest});
        m_atlas.add(randomImage(13, 3, TexelEncoding::Srgb8, random, 0, 1), "j", W::Mirror, W::Clamp,
                    {true, true, M::Nearest});
        m_atlas.add(randomImage(5, 9, TexelEncoding::Srgb8, random, 0, 1), "k", W::Repeat, W::Repeat,
                    {false, true, M::None});
        m_atlas.add(randomImage(12, 12, TexelEncoding::Half, random, 0, 1), "l", W::Clamp, W::Clamp,
                    {true, false, M::None});
        m_buffers = m_atlas.pack();
    }

    /// Random uv over several periods, lod over and beyond [0, levels - 1].
    std::vector<Lookup> randomLookups(size_t perTexture) const
    {
        std::mt19937 random(7);
        std::uniform_real_distribution<float> uv(-2.5f, 3.5f);
        std::vector<Lookup> lookups;
        for (uint32_t t = 0; t < m_buffers.records.size(); ++t) {
            std::uniform_real_distribution<float> lod(-1.0f, float(m_buffers.records[t].levels) + 0.5f);
            for (size_t i = 0; i < perTexture; ++i) lookups.push_back({t, uv(random), uv(random), lod(random)});
        }
        return lookups;
    }

    /// Exact texel centres of every level (at integer lods), the image edges
    /// and corners, and points just past them for every wrap mode.
    std::vector<Lookup> structuredLookups() const
    {
        std::vector<Lookup> lookups;
        for (uint32_t t = 0; t < m_buffers.records.size(); ++t) {
            const gpu::TextureRecord& r = m_buffers.records[t];
            for (uint32_t level = 0; level < r.levels; ++level) {
                const uint32_t w = std::max(1u, r.width >> level), h = std::max(1u, r.height >> level);
                for (uint32_t y = 0; y < h; ++y)
                    for (uint32_t x = 0; x < w; ++x)
                        lookups.push_back({t, (x + 0.5f) / float(w), 1.0f - (y + 0.5f) / float(h), float(level)});
            }
            const float edges[] = {0.0f, 1.0f, -1.0f, 2.0f, 1e-4f, -1e-4f, 1.0f - 1e-4f, 1.0f + 1e-4f, 0.5f, -0.75f};
            for (float u : edges)
                for (float v : edges)
                    for (float lod : {0.0f, 0.5f, 1.25f}) lookups.push_back({t, u, v, lod});
        }
        return lookups;
    }

    TextureAtlas m_atlas;
    TextureBuffers m_buffers;
};

constexpr double kTolerance = 2e-5; // float32 arithmetic over values of at most 4

/// Largest |GPU - reference| over all lookups and channels, with the worst case in `where`.
double maxError(const std::vector<Lookup>& lookups, const std::vector<Rgba>& gpuResults,
                const ReferenceSampler& reference, std::string& where)
{
    double worst = 0.0;
    for (size_t i = 0; i < lookups.size(); ++i) {
        const Lookup& l = lookups[i];
        const Rgba expected = reference.sample(l.texture, l.u, l.v, l.lod);
        for (int c = 0; c < 4; ++c) {
            const double error = std::abs(gpuResults[i][c] - expected[c]);
            if (!(error <= worst)) {
                worst = std::isnan(error) ? std::numeric_limits<double>::infinity() : error;
                where = "texture " + std::to_string(l.texture) + " uv (" + std::to_string(l.u) + ", " +
                        std::to_string(l.v) + ") lod " + std::to_string(l.lod) + " channel " + std::to_string(c) +
                        ": gpu " + std::to_string(gpuResults[i][c]) + " reference " + std::to_string(expected[c]);
            }
        }
    }
    return worst;
}

TEST_F(TextureProbe, RandomLookupsMatchTheReference)
{
    const std::vector<Lookup> lookups = randomLookups(2000);
    const std::vector<Rgba> results = sampleOnGpu(m_buffers, lookups);
    std::string where;
    const double error = maxError(lookups, results, ReferenceSampler(m_buffers), where);
    reportStat("texture_random_max_error", error);
    EXPECT_LT(error, kTolerance) << where;
    // The comparison is sharp enough to see a wrong v convention.
    EXPECT_GT(maxError(lookups, results, ReferenceSampler(m_buffers, false), where), 0.05);
    // And to see a filter ignored: the same lookups without the filters.
    TextureBuffers unfiltered = m_buffers;
    for (gpu::TextureRecord& record : unfiltered.records) record.filters = 0;
    EXPECT_GT(maxError(lookups, results, ReferenceSampler(unfiltered), where), 0.05);
}

TEST_F(TextureProbe, TexelCentresEdgesAndWrapModesMatchTheReference)
{
    const std::vector<Lookup> lookups = structuredLookups();
    const std::vector<Rgba> results = sampleOnGpu(m_buffers, lookups);
    std::string where;
    const double error = maxError(lookups, results, ReferenceSampler(m_buffers), where);
    reportStat("texture_structured_max_error", error);
    EXPECT_LT(error, kTolerance) << where;
}

TEST_F(TextureProbe, LodOutsideTheChainIsClamped)
{
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const uint32_t f = 5; // 16x16: levels 0..4
    const std::vector<Lookup> lookups{{f, 0.3f, 0.6f, nan}, {f, 0.3f, 0.6f, -inf}, {f, 0.3f, 0.6f, -3.0f},
                                      {f, 0.3f, 0.6f, inf}, {f, 0.3f, 0.6f, 99.0f}, {f, 0.3f, 0.6f, 4.0f},
                                      {f, 0.3f, 0.6f, 0.0f}};
    const std::vector<Rgba> r = sampleOnGpu(m_buffers, lookups);
    for (size_t i : {0, 1, 2})
        for (int c = 0; c < 4; ++c) EXPECT_EQ(r[i][c], r[6][c]) << "lookup " << i << " is level 0";
    for (size_t i : {3, 4})
        for (int c = 0; c < 4; ++c) EXPECT_EQ(r[i][c], r[5][c]) << "lookup " << i << " is the 1x1 level";
    EXPECT_NE(r[5][0], r[6][0]);
}

// Every 8-bit sRGB code sampled at its texel centre: the shader's decoding
// against the exact formula in double.
TEST_F(TextureProbe, ShaderDecodesEverySrgbCode)
{
    TextureImage ramp{RgbaImage(256, 1), TexelEncoding::Srgb8};
    for (uint32_t code = 0; code < 256; ++code) {
        float* texel = ramp.pixels.at(code, 0);
        texel[0] = texel[1] = texel[2] = float(srgbReference(code / 255.0));
        texel[3] = float(code / 255.0);
    }
    TextureAtlas atlas;
    atlas.add(ramp, "ramp", TextureWrap::Clamp, TextureWrap::Clamp);
    const TextureBuffers buffers = atlas.pack();
    for (uint32_t code = 0; code < 256; ++code) ASSERT_EQ(buffers.texels[code] & 0xffu, code);
    std::vector<Lookup> lookups;
    for (uint32_t code = 0; code < 256; ++code) lookups.push_back({0, (code + 0.5f) / 256.0f, 0.5f, 0.0f});
    const std::vector<Rgba> results = sampleOnGpu(buffers, lookups);
    double worst = 0.0;
    for (uint32_t code = 0; code < 256; ++code) {
        const double expected = srgbReference(code / 255.0);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(results[code][c], expected, 1e-6 + 4e-6 * expected) << "code " << code;
            worst = std::max(worst, std::abs(results[code][c] - expected) / std::max(expected, 1e-3));
        }
        EXPECT_NEAR(results[code][3], code / 255.0, 1e-7) << "alpha is linear, code " << code;
    }
    reportStat("srgb_decode_max_relative_error", worst);
}

// Filtering happens after decoding: halfway between codes 0 and 255 is 0.5
// linear, not the decoding of the average code (0.21).
TEST_F(TextureProbe, FiltersDecodedValues)
{
    TextureImage pair{RgbaImage(2, 1), TexelEncoding::Srgb8};
    std::fill(pair.pixels.rgba.begin() + 4, pair.pixels.rgba.end(), 1.0f);
    TextureAtlas atlas;
    atlas.add(pair, "pair", TextureWrap::Clamp, TextureWrap::Clamp);
    const std::vector<Rgba> results = sampleOnGpu(atlas.pack(), {{0, 0.5f, 0.5f, 0.0f}, {0, 0.5f, 0.5f, 1.0f}});
    EXPECT_NEAR(results[0][0], 0.5, 1e-6);
    // The 1x1 level: the linear mean 0.5, stored as sRGB code 188.
    EXPECT_NEAR(results[1][0], srgbReference(188 / 255.0), 1e-6);
}

// Closed forms: a 4 x 4 image whose left half is 1 and right half 0 (half
// floats, exact). Level 1 is the same halves at 2 x 2, level 2 their mean 0.5;
// at u = 0.3 level 0's texel is 1 and level 1's bilinear value 0.9.
TEST_F(TextureProbe, MinificationFiltersReadTheLevelsTheyName)
{
    TextureImage halves{RgbaImage(4, 4), TexelEncoding::Half};
    for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 4; ++x) std::fill_n(halves.pixels.at(x, y), 4, x < 2 ? 1.0f : 0.0f);
    using W = TextureWrap;
    using M = TextureFilter::Mip;
    TextureAtlas atlas;
    atlas.add(halves, "trilinear", W::Clamp, W::Clamp);
    atlas.add(halves, "nearest level", W::Clamp, W::Clamp, {false, false, M::Nearest});
    atlas.add(halves, "level 0 nearest", W::Clamp, W::Clamp, {false, true, M::None});
    const std::vector<Rgba> r = sampleOnGpu(atlas.pack(), {{0, 0.3f, 0.5f, 1.5f},
                                                           {1, 0.3f, 0.5f, 1.4f},
                                                           {1, 0.3f, 0.5f, 1.6f},
                                                           {2, 0.3f, 0.5f, 2.0f},
                                                           {2, 0.6f, 0.5f, 2.0f}});
    EXPECT_NEAR(r[0][0], 0.5 * 0.9 + 0.5 * 0.5, 1e-6) << "trilinear: levels 1 and 2 blended";
    EXPECT_NEAR(r[1][0], 0.9, 1e-6) << "lod 1.4: level 1 alone";
    EXPECT_EQ(r[2][0], 0.5) << "lod 1.6: level 2 alone";
    EXPECT_EQ(r[3][0], 1.0) << "no mip maps: level 0's nearest texel";
    EXPECT_EQ(r[4][0], 0.0) << "no mip maps: level 0's nearest texel";
}

TEST_F(TextureProbe, RayConeLodFollowsTheFormula)
{
    const uint32_t f = 5; // 16 x 16
    struct Case {
        float coneWidth, cosTheta, uvPerWorld;
    };
    const Case cases[] = {{0.01f, 1.0f, 1.0f}, {0.01f, -0.5f, 4.0f}, {0.2f, 0.1f, 0.25f}, {1e-3f, 0.9f, 100.0f},
                          {0.05f, 0.0f, 1.0f}};
    std::vector<float> input;
    for (const Case& c : cases) input.insert(input.end(), {1.0f, float(f), c.coneWidth, c.cosTheta, c.uvPerWorld});
    const std::vector<float> out =
        runProbeWithBuffers("texture_probe", input, std::size(cases) * 4, uint32_t(std::size(cases)),
                            {{gpu::BINDING_TEXTURE_TEXELS, probeBytes(m_buffers.texels)},
                             {gpu::BINDING_TEXTURE_RECORDS, probeBytes(m_buffers.records)}});
    for (size_t i = 0; i < std::size(cases); ++i) {
        const Case& c = cases[i];
        const double expected = 0.5 * std::log2(256.0 * c.uvPerWorld) +
                                std::log2(c.coneWidth / std::max(std::abs(double(c.cosTheta)), 1e-4));
        EXPECT_NEAR(out[i * 4], expected, 1e-4) << i;
    }
}

} // namespace
} // namespace vkrt::test
