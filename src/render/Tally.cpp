#include "render/Tally.h"

#include "util/Error.h"

#include <cmath>
#include <limits>
#include <sstream>

namespace vkrt {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

bool sameSize(const Image& a, const Image& b) { return a.width == b.width && a.height == b.height; }

Image filled(uint32_t width, uint32_t height) { return Image(width, height); }

/// Adds (nb, mean b, m2 b) into (na, mean a, m2 a) for one value: Chan et al. 1979.
void addMoments(double& na, double& meanA, double* m2a, double nb, double meanB, double m2b)
{
    const double n = na + nb;
    if (nb == 0.0) return;
    const double delta = meanB - meanA;
    if (m2a) *m2a += m2b + delta * delta * na * nb / n;
    meanA += delta * nb / n;
    na = n;
}

/// Per value of `count` / `mean` (and `m2`), the merged sums of every tally's images.
void mergeInto(const std::vector<const Image*>& counts, const std::vector<const Image*>& means,
               const std::vector<const Image*>& m2s, Image& count, Image& mean, Image* m2)
{
    const size_t values = count.rgb.size();
    for (size_t v = 0; v < values; ++v) {
        double n = 0.0, mu = 0.0, squares = 0.0;
        for (size_t t = 0; t < counts.size(); ++t)
            addMoments(n, mu, m2 ? &squares : nullptr, counts[t]->rgb[v], means[t]->rgb[v], m2 ? m2s[t]->rgb[v] : 0.0);
        count.rgb[v] = float(n);
        mean.rgb[v] = float(mu);
        if (m2) m2->rgb[v] = float(squares);
    }
}

const Image& layer(const ExrContents& contents, const std::string& name, const std::string& file)
{
    const auto found = contents.layers.find(name);
    if (found == contents.layers.end())
        throw InputError(file + ": no layer '" + name + "': not a shard written by `vkrt render --shard`");
    if (!sameSize(found->second, contents.image))
        throw InputError(file + ": layer '" + name + "' is not the image's size");
    return found->second;
}

/// sampleEnd - sampleBegin from the shard's metadata: no pixel can have more samples.
int64_t shardSampleCount(const ExrContents& contents, const std::string& file)
{
    auto attribute = [&](const char* key) {
        const auto found = contents.metadata.find(key);
        const auto* value = found == contents.metadata.end() ? nullptr : std::get_if<int64_t>(&found->second);
        if (!value)
            throw InputError(file + ": no integer '" + key +
                             "' attribute: not a shard written by `vkrt render --shard`");
        return *value;
    };
    const int64_t begin = attribute("sampleBegin"), end = attribute("sampleEnd");
    if (begin < 0 || end <= begin)
        throw InputError(file + ": sample range [" + std::to_string(begin) + ", " + std::to_string(end) +
                         ") is empty or negative");
    return end - begin;
}

std::string formatValue(float value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

/// Names the first value of `image` that `valid` refuses, with its pixel: "FILE: tally.count at pixel (x, y) is V, but
/// ...".
template <typename Valid>
void checkEveryValue(const Image& image, const std::string& name, const std::string& file, const std::string& rule,
                     Valid valid)
{
    for (size_t v = 0; v < image.rgb.size(); ++v) {
        if (valid(image.rgb[v])) continue;
        const size_t pixel = v / 3;
        throw InputError(file + ": " + name + " at pixel (" + std::to_string(pixel % image.width) + ", " +
                         std::to_string(pixel / image.width) + ") is " + formatValue(image.rgb[v]) + ", but " + rule);
    }
}

/// Counts are whole numbers of samples within the shard's range; means and sums are finite.
void checkTallyValues(const Tally& tally, int64_t samples, const std::string& file)
{
    const std::string countRule =
        "a count is a whole number from 0 to the " + std::to_string(samples) + " samples the shard covers";
    auto isCount = [&](float n) { return n >= 0.0f && n == std::floor(n) && double(n) <= double(samples); };
    auto isFinite = [](float x) { return std::isfinite(x); };
    checkEveryValue(tally.count, "tally.count", file, countRule, isCount);
    checkEveryValue(tally.mean, "tally.mean", file, "a mean must be finite", isFinite);
    if (tally.m2)
        checkEveryValue(*tally.m2, "tally.m2", file, "a sum of squared deviations is finite and >= 0",
                        [](float x) { return std::isfinite(x) && x >= 0.0f; });
    for (size_t b = 0; b < tally.batchMean.size(); ++b) {
        const std::string batch = "tally.batch" + std::to_string(b);
        checkEveryValue(tally.batchCount[b], batch + ".count", file, countRule, isCount);
        checkEveryValue(tally.batchMean[b], batch + ".mean", file, "a mean must be finite", isFinite);
    }
}

} // namespace

Image tallyMean(const Tally& tally)
{
    if (tally.batchMean.empty()) return tally.mean;
    // The mean of the batch means, where every batch has a sample (Renderer::mean).
    Image image = tally.mean;
    const size_t batches = tally.batchMean.size();
    for (size_t v = 0; v < image.rgb.size(); ++v) {
        double sum = 0.0;
        bool every = true;
        for (size_t b = 0; b < batches; ++b) {
            every = every && tally.batchCount[b].rgb[v] > 0.0f;
            sum += tally.batchMean[b].rgb[v];
        }
        if (every) image.rgb[v] = float(sum / double(batches));
    }
    return image;
}

std::optional<Image> tallyVarianceOfMean(const Tally& tally)
{
    if (!tally.hasVariance()) return std::nullopt;
    Image variance = filled(tally.mean.width, tally.mean.height);
    for (size_t v = 0; v < variance.rgb.size(); ++v) {
        double result = kInfinity;
        if (tally.m2) {
            const double n = tally.count.rgb[v];
            if (n >= 2.0) result = double(tally.m2->rgb[v]) / ((n - 1.0) * n);
        } else {
            const size_t k = tally.batchMean.size();
            double sum = 0.0;
            bool every = k >= 2;
            for (size_t b = 0; b < k; ++b) {
                every = every && tally.batchCount[b].rgb[v] > 0.0f;
                sum += tally.batchMean[b].rgb[v];
            }
            if (every) {
                const double mean = sum / double(k);
                double squares = 0.0;
                for (size_t b = 0; b < k; ++b) squares += std::pow(tally.batchMean[b].rgb[v] - mean, 2.0);
                result = squares / (double(k) * double(k - 1));
            }
        }
        variance.rgb[v] = std::isfinite(result) ? float(result) : kInfinity;
    }
    return variance;
}

Tally mergeTallies(const std::vector<Tally>& tallies)
{
    VKRT_CHECK(!tallies.empty());
    const Tally& first = tallies.front();
    for (const Tally& t : tallies)
        VKRT_CHECK(sameSize(t.mean, first.mean) && t.m2.has_value() == first.m2.has_value() &&
                   t.batchMean.size() == first.batchMean.size());
    Tally merged;
    merged.count = filled(first.mean.width, first.mean.height);
    merged.mean = merged.count;
    if (first.m2) merged.m2 = merged.count;
    std::vector<const Image*> counts, means, m2s;
    for (const Tally& t : tallies) {
        counts.push_back(&t.count);
        means.push_back(&t.mean);
        if (t.m2) m2s.push_back(&*t.m2);
    }
    mergeInto(counts, means, m2s, merged.count, merged.mean, merged.m2 ? &*merged.m2 : nullptr);
    for (size_t b = 0; b < first.batchMean.size(); ++b) {
        std::vector<const Image*> batchCounts, batchMeans;
        for (const Tally& t : tallies) {
            batchCounts.push_back(&t.batchCount[b]);
            batchMeans.push_back(&t.batchMean[b]);
        }
        merged.batchCount.push_back(filled(first.mean.width, first.mean.height));
        merged.batchMean.push_back(merged.batchCount.back());
        mergeInto(batchCounts, batchMeans, {}, merged.batchCount.back(), merged.batchMean.back(), nullptr);
    }
    return merged;
}

void addTallyLayers(const Tally& tally, std::map<std::string, Image>& layers)
{
    layers["tally.count"] = tally.count;
    layers["tally.mean"] = tally.mean;
    if (tally.m2) layers["tally.m2"] = *tally.m2;
    for (size_t b = 0; b < tally.batchMean.size(); ++b) {
        layers["tally.batch" + std::to_string(b) + ".count"] = tally.batchCount[b];
        layers["tally.batch" + std::to_string(b) + ".mean"] = tally.batchMean[b];
    }
}

Tally readTally(const ExrContents& contents, const std::string& file)
{
    const int64_t samples = shardSampleCount(contents, file);
    Tally tally;
    tally.count = layer(contents, "tally.count", file);
    tally.mean = layer(contents, "tally.mean", file);
    if (contents.layers.count("tally.m2")) tally.m2 = layer(contents, "tally.m2", file);
    for (size_t b = 0; contents.layers.count("tally.batch" + std::to_string(b) + ".mean"); ++b) {
        tally.batchCount.push_back(layer(contents, "tally.batch" + std::to_string(b) + ".count", file));
        tally.batchMean.push_back(layer(contents, "tally.batch" + std::to_string(b) + ".mean", file));
    }
    checkTallyValues(tally, samples, file);
    return tally;
}

} // namespace vkrt
