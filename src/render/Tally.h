#pragma once
// What a render has accumulated, per pixel, in a form that adds up exactly:
// the accepted sample count and mean, and the variance estimator's own sums
// (Welford's m2 for independent samples; per Sobol' batch its count and mean).
// A shard of a render (`vkrt render --shard i/n`) writes its tally into its
// EXR as layers, and `vkrt merge` adds the shards' tallies in double
// precision, so the merged image, variance and error estimate are those of
// one run over all the samples, to float rounding (docs/farm.md).
#include "io/ExrFile.h"
#include "io/Image.h"

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

/// Per-pixel sums; every image has the same size. Counts are stored in all three channels.
struct Tally {
    Image count;                   ///< accepted samples
    Image mean;                    ///< of the accepted samples
    std::optional<Image> m2;       ///< independent samples with variance: sum of squared deviations
    std::vector<Image> batchCount; ///< Sobol' batches with variance: per batch, its samples...
    std::vector<Image> batchMean;  ///< ... and their mean

    bool hasVariance() const { return m2.has_value() || !batchMean.empty(); }
};

/// The image the tally stands for: the mean (with batches: the mean of the
/// batch means, as Renderer::mean), and the variance of that mean (+inf where
/// too few samples), as Renderer::varianceOfMean computes them.
Image tallyMean(const Tally& tally);
std::optional<Image> tallyVarianceOfMean(const Tally& tally);

/// The sum of tallies of disjoint sample sets of the same pixels (Chan et al.'s
/// pairwise update for m2), in double precision. All must have the same size
/// and the same kind of variance sums.
Tally mergeTallies(const std::vector<Tally>& tallies);

/// As EXR layers ("tally.count", "tally.mean", "tally.m2", "tally.batchK.count",
/// "tally.batchK.mean"), and back; readTally throws InputError naming `file`
/// when a layer is missing or has the wrong size, the metadata has no sample
/// range (sampleBegin, sampleEnd), or a value is one no render writes: a count
/// that is not a whole number in [0, sampleEnd - sampleBegin], a non-finite
/// mean, a negative or non-finite m2 (the message names the layer and pixel).
void addTallyLayers(const Tally& tally, std::map<std::string, Image>& layers);
Tally readTally(const ExrContents& contents, const std::string& file);

} // namespace vkrt
