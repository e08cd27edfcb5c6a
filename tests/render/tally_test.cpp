// Tallies (render/Tally.h) add up exactly: tallies of disjoint sample sets,
// merged, equal the tally made directly from all the samples, computed here
// in double from the samples themselves.
#include "render/Tally.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace vkrt {
namespace {

/// One pixel's samples per channel; the image is 2 x 1 with the same samples in every channel + offset.
using Samples = std::vector<double>;

Image grey(double value)
{
    Image image(2, 1);
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float(value + double(i));
    return image;
}

/// count, mean, m2 of samples (plus per-channel offset i: the mean shifts, m2 does not).
Tally independentTally(const Samples& s)
{
    double mean = 0.0;
    for (double x : s) mean += x;
    mean /= double(s.size());
    double m2 = 0.0;
    for (double x : s) m2 += (x - mean) * (x - mean);
    Tally t;
    t.count = Image(2, 1);
    for (float& n : t.count.rgb) n = float(s.size());
    t.mean = grey(mean);
    t.m2 = Image(2, 1);
    for (float& v : t.m2->rgb) v = float(m2);
    return t;
}

/// Batch b holds the samples of global index f with f % k == b (lib/sobol.glsl's rule).
Tally batchedTally(const Samples& all, size_t first, size_t end, size_t k)
{
    Samples mine(all.begin() + long(first), all.begin() + long(end));
    Tally t = independentTally(mine);
    t.m2.reset();
    for (size_t b = 0; b < k; ++b) {
        double sum = 0.0, n = 0.0;
        for (size_t f = first; f < end; ++f)
            if (f % k == b) sum += all[f], n += 1.0;
        Image count(2, 1);
        for (float& c : count.rgb) c = float(n);
        t.batchCount.push_back(count);
        t.batchMean.push_back(n > 0 ? grey(sum / n) : Image(2, 1));
    }
    return t;
}

Samples randomSamples(size_t n)
{
    std::mt19937 rng(7);
    std::lognormal_distribution<double> radiance(0.0, 1.5);
    Samples s(n);
    for (double& x : s) x = radiance(rng);
    return s;
}

void expectClose(const Image& a, const Image& b, double relative, const char* what)
{
    for (size_t i = 0; i < a.rgb.size(); ++i)
        EXPECT_NEAR(a.rgb[i], b.rgb[i], relative * std::max(1.0, std::abs(double(b.rgb[i])))) << what << " " << i;
}

TEST(TallyMerge, DisjointIndependentTalliesAddUpToTheWholeSampleSet)
{
    const Samples all = randomSamples(1000);
    const std::vector<std::pair<size_t, size_t>> ranges = {{0, 1}, {1, 333}, {333, 334}, {334, 1000}};
    std::vector<Tally> parts;
    for (auto [a, b] : ranges) parts.push_back(independentTally(Samples(all.begin() + long(a), all.begin() + long(b))));
    const Tally merged = mergeTallies(parts), whole = independentTally(all);
    expectClose(merged.count, whole.count, 0.0, "count");
    expectClose(merged.mean, whole.mean, 1e-6, "mean");
    expectClose(*merged.m2, *whole.m2, 1e-5, "m2");
    expectClose(*tallyVarianceOfMean(merged), *tallyVarianceOfMean(whole), 1e-5, "variance of the mean");
    // The variance of the mean is the sample variance over n.
    double mean = whole.mean.rgb[0], squares = 0.0;
    for (double x : all) squares += (x - mean) * (x - mean);
    EXPECT_NEAR(tallyVarianceOfMean(merged)->rgb[0], squares / 999.0 / 1000.0, 1e-6 * squares / 999e3);
}

TEST(TallyMerge, SobolBatchTalliesAddUpToTheWholeSampleSet)
{
    const Samples all = randomSamples(96);
    const size_t k = 8;
    std::vector<Tally> parts = {batchedTally(all, 0, 5, k), batchedTally(all, 5, 50, k), batchedTally(all, 50, 96, k)};
    const Tally merged = mergeTallies(parts), whole = batchedTally(all, 0, 96, k);
    for (size_t b = 0; b < k; ++b) {
        expectClose(merged.batchCount[b], whole.batchCount[b], 0.0, "batch count");
        expectClose(merged.batchMean[b], whole.batchMean[b], 1e-6, "batch mean");
    }
    expectClose(tallyMean(merged), tallyMean(whole), 1e-6, "mean of batch means");
    expectClose(*tallyVarianceOfMean(merged), *tallyVarianceOfMean(whole), 1e-5, "variance");
    // A first part of 5 samples leaves batches empty: no estimate yet (+inf), never 0.
    EXPECT_TRUE(std::isinf(tallyVarianceOfMean(parts[0])->rgb[0]));
}

/// A shard's EXR contents holding tally `t` of samples [begin, end).
ExrContents shardOf(const Tally& t, int64_t begin, int64_t end)
{
    ExrContents exr;
    exr.image = t.mean;
    addTallyLayers(t, exr.layers);
    exr.metadata["sampleBegin"] = begin;
    exr.metadata["sampleEnd"] = end;
    return exr;
}

TEST(TallyMerge, LayersRoundTripAndMissingOnesAreNamed)
{
    const Tally t = batchedTally(randomSamples(16), 0, 16, 8);
    ExrContents exr = shardOf(t, 0, 16);
    const Tally back = readTally(exr, "shard.exr");
    ASSERT_EQ(back.batchMean.size(), 8u);
    expectClose(back.batchMean[3], t.batchMean[3], 0.0, "batch mean");
    exr.layers.erase("tally.count");
    try {
        readTally(exr, "shard.exr");
        ADD_FAILURE() << "no error for a missing layer";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("shard.exr: no layer 'tally.count'"), std::string::npos) << e.what();
    }
}

/// readTally's message for `exr`, or "" when it accepts it.
std::string refusal(const ExrContents& exr)
{
    try {
        readTally(exr, "shard.exr");
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

TEST(TallyRead, PoisonedValuesAreRefusedNamingLayerAndPixel)
{
    const Tally t = independentTally({1.0, 2.0}); // 2 x 1 pixels, 2 samples each
    struct Case {
        std::string layer;
        float value;
        std::string message;
    };
    const std::vector<Case> cases = {
        {"tally.mean", NAN, "shard.exr: tally.mean at pixel (1, 0) is nan, but a mean must be finite"},
        {"tally.mean", INFINITY, "tally.mean at pixel (1, 0) is inf"},
        {"tally.count", 1e30f,
         "shard.exr: tally.count at pixel (1, 0) is 1e+30, but a count is a whole number from 0 "
         "to the 2 samples the shard covers"},
        {"tally.count", -1.0f, "tally.count at pixel (1, 0) is -1"},
        {"tally.count", 3.0f, "tally.count at pixel (1, 0) is 3, but"},
        {"tally.count", 1.5f, "tally.count at pixel (1, 0) is 1.5, but"},
        {"tally.count", NAN, "tally.count at pixel (1, 0) is nan"},
        {"tally.m2", -0.5f, "tally.m2 at pixel (1, 0) is -0.5, but a sum of squared deviations is finite and >= 0"},
        {"tally.m2", INFINITY, "tally.m2 at pixel (1, 0) is inf"},
    };
    ASSERT_EQ(refusal(shardOf(t, 0, 2)), "") << "the unpoisoned tally is accepted";
    for (const Case& c : cases) {
        ExrContents exr = shardOf(t, 0, 2);
        exr.layers.at(c.layer).rgb[4] = c.value; // pixel (1, 0), green
        const std::string message = refusal(exr);
        EXPECT_NE(message.find(c.message), std::string::npos) << c.layer << " = " << c.value << ": " << message;
    }
}

TEST(TallyRead, BatchValuesAndTheSampleRangeAreChecked)
{
    const Tally t = batchedTally(randomSamples(16), 0, 16, 8);
    ExrContents exr = shardOf(t, 0, 16);
    exr.layers.at("tally.batch3.count").rgb[0] = 17.0f;
    EXPECT_NE(refusal(exr).find("tally.batch3.count at pixel (0, 0) is 17"), std::string::npos) << refusal(exr);
    exr = shardOf(t, 0, 16);
    exr.layers.at("tally.batch5.mean").rgb[2] = NAN;
    EXPECT_NE(refusal(exr).find("tally.batch5.mean at pixel (0, 0) is nan"), std::string::npos) << refusal(exr);
    // Counts of 16 in a shard of 8 samples: the range, not the layer, is the limit.
    exr = shardOf(t, 8, 16);
    EXPECT_NE(refusal(exr).find("tally.count at pixel (0, 0) is 16, but a count is a whole number from 0 to the 8"),
              std::string::npos)
        << refusal(exr);
    exr = shardOf(t, 0, 16);
    exr.metadata.erase("sampleEnd");
    EXPECT_NE(refusal(exr).find("shard.exr: no integer 'sampleEnd' attribute"), std::string::npos) << refusal(exr);
}

} // namespace
} // namespace vkrt
