// `vkrt merge SHARD.exr... -o out.exr`: adds the shards of one render
// (`vkrt render --shard i/n`) into the image one run over all their samples
// would give: the shards must belong together (scene, size, seed, sampler,
// integrator, kernel, shard count, total spp) and cover disjoint sample
// ranges; their tallies are added in double precision (render/Tally.h), and
// the merged file is itself a shard of the union, so merges can be merged.
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "io/ExrFile.h"
#include "io/OutputPaths.h"
#include "render/Outcome.h"
#include "render/Tally.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

namespace {

struct MergeOptions {
    std::vector<std::string> shards;
    std::string output;
    bool allowMissing = false;
    bool variance = false;
};

/// The metadata every shard of one render shares.
constexpr const char* kSharedKeys[] = {"sceneHash", "seed", "sampler", "integrator", "kernelVariant", "totalSpp"};

std::string text(const MetadataValue& value)
{
    if (const auto* s = std::get_if<std::string>(&value)) return *s;
    if (const auto* i = std::get_if<int64_t>(&value)) return std::to_string(*i);
    return std::to_string(std::get<double>(value));
}

const MetadataValue& required(const Metadata& metadata, const std::string& key, const std::string& file)
{
    const auto found = metadata.find(key);
    if (found == metadata.end())
        throw InputError(file + ": no '" + key + "' attribute: not a shard written by `vkrt render --shard`");
    return found->second;
}

int64_t integer(const Metadata& metadata, const std::string& key, const std::string& file)
{
    const auto* value = std::get_if<int64_t>(&required(metadata, key, file));
    if (!value) throw InputError(file + ": attribute '" + key + "' is not an integer");
    return *value;
}

/// A shard as its header describes it: merge checks every shard's header
/// before it reads any shard's pixels.
struct Shard {
    std::string file;
    ExrHeader header;
    int64_t begin = 0, end = 0;
    bool interrupted = false;
};

/// Reads and checks `file`'s header alone, of the size `expected` when given.
Shard readShard(const std::string& file, const std::optional<ExpectedSize>& expected)
{
    Shard shard{file, readExrHeader(file, expected)};
    const Metadata& metadata = shard.header.metadata;
    required(metadata, "shard", file);
    shard.begin = integer(metadata, "sampleBegin", file);
    shard.end = integer(metadata, "sampleEnd", file);
    if (shard.begin < 0 || shard.end <= shard.begin)
        throw InputError(file + ": sample range [" + std::to_string(shard.begin) + ", " + std::to_string(shard.end) +
                         ") is empty or negative");
    const auto stopped = metadata.find("stoppedBy");
    shard.interrupted = stopped != metadata.end() && text(stopped->second) == "interrupted";
    return shard;
}

/// The size every shard must have: the first one's.
ExpectedSize sizeOfFirst(const std::vector<Shard>& shards)
{
    const Shard& first = shards.front();
    return {first.header.width, first.header.height, first.file + " is"};
}

/// Every shard's header, each checked against the first's size as it is read.
std::vector<Shard> readShardHeaders(const std::vector<std::string>& files)
{
    std::vector<Shard> shards;
    for (const std::string& file : files) {
        std::optional<ExpectedSize> size;
        if (!shards.empty()) size = sizeOfFirst(shards);
        shards.push_back(readShard(file, size));
    }
    return shards;
}

/// Every shard like the first (naming the odd one), and no two ranges
/// overlapping. Sizes were checked as the headers were read.
void checkTheyBelongTogether(const std::vector<Shard>& shards)
{
    const Shard& first = shards.front();
    for (const Shard& s : shards) {
        for (const char* key : kSharedKeys) {
            const std::string mine = text(required(s.header.metadata, key, s.file)),
                              theirs = text(required(first.header.metadata, key, first.file));
            if (mine != theirs)
                throw InputError(s.file + ": " + key + " is '" + mine + "', but " + first.file + " has '" + theirs +
                                 "': not shards of one render");
        }
    }
    std::vector<const Shard*> sorted;
    for (const Shard& s : shards) sorted.push_back(&s);
    std::sort(sorted.begin(), sorted.end(), [](const Shard* a, const Shard* b) { return a->begin < b->begin; });
    for (size_t i = 1; i < sorted.size(); ++i)
        if (sorted[i]->begin < sorted[i - 1]->end)
            throw InputError(sorted[i]->file + ": samples [" + std::to_string(sorted[i]->begin) + ", " +
                             std::to_string(sorted[i]->end) + ") overlap those of " + sorted[i - 1]->file + " [" +
                             std::to_string(sorted[i - 1]->begin) + ", " + std::to_string(sorted[i - 1]->end) + ")");
}

/// The sample ranges of [0, total) that no shard covers, as "[a, b)" texts.
std::vector<std::string> missingRanges(std::vector<Shard>& shards, int64_t total)
{
    std::sort(shards.begin(), shards.end(), [](const Shard& a, const Shard& b) { return a.begin < b.begin; });
    std::vector<std::string> missing;
    int64_t next = 0;
    for (const Shard& s : shards) {
        if (s.begin > next) missing.push_back("[" + std::to_string(next) + ", " + std::to_string(s.begin) + ")");
        next = std::max(next, s.end);
    }
    if (next < total) missing.push_back("[" + std::to_string(next) + ", " + std::to_string(total) + ")");
    return missing;
}

std::string joined(const std::vector<std::string>& items, const std::string& separator)
{
    std::string out;
    for (const std::string& item : items) out += (out.empty() ? "" : separator) + item;
    return out;
}

Metadata mergedMetadata(const std::vector<Shard>& shards, int64_t spp, const std::vector<std::string>& missing)
{
    Metadata metadata = shards.front().header.metadata;
    for (const char* key :
         {"shard", "stoppedBy", "estimatedRmse", "estimatedRelMse", "renderSeconds", "device", "driver", "savedBy"})
        metadata.erase(key);
    double seconds = 0.0, rejected = 0.0;
    std::vector<std::string> files, interrupted;
    for (const Shard& s : shards) {
        const Metadata& shardMetadata = s.header.metadata;
        if (const auto* t = std::get_if<double>(&shardMetadata.at("renderSeconds"))) seconds += *t;
        if (const auto found = shardMetadata.find("rejectedSamples"); found != shardMetadata.end())
            if (const auto* n = std::get_if<int64_t>(&found->second)) rejected += double(*n);
        files.push_back(s.file);
        if (s.interrupted) interrupted.push_back(s.file);
    }
    metadata["spp"] = spp;
    metadata["sampleBegin"] = shards.front().begin;
    metadata["sampleEnd"] = shards.back().end;
    metadata["shard"] = std::string("merged");
    metadata["mergedShards"] = joined(files, ", ");
    metadata["renderSeconds"] = seconds; // summed over the shards
    metadata["rejectedSamples"] = int64_t(rejected);
    if (!missing.empty()) metadata["missingSamples"] = joined(missing, " ");
    if (!interrupted.empty()) metadata["interruptedShards"] = joined(interrupted, ", ");
    return metadata;
}

/// One shard's pixels at a time, of which only the tally is kept: a 4K
/// shard's image and layers are ~0.5 GB, its tally part of that.
std::vector<Tally> readTallies(const std::vector<Shard>& shards)
{
    const ExpectedSize size = sizeOfFirst(shards);
    std::vector<Tally> tallies;
    for (const Shard& s : shards) tallies.push_back(readTally(readExr(s.file, size), s.file));
    return tallies;
}

/// Before reading anything: `-o` must not be one of the shards (it would be destroyed) and must be writable.
void checkMergeFiles(const MergeOptions& options)
{
    std::vector<NamedFile> inputs;
    for (const std::string& file : options.shards) inputs.push_back({"shard", file});
    checkOutputs(inputs, {{"-o", options.output}});
}

/// Bad shards throw InputError (exit 2, from main); a merge written is Passed.
Outcome runMerge(const MergeOptions& options)
{
    checkMergeFiles(options);
    // Headers first: a bad shard is refused before any good shard's pixels are read.
    std::vector<Shard> shards = readShardHeaders(options.shards);
    checkTheyBelongTogether(shards);
    const int64_t total = integer(shards.front().header.metadata, "totalSpp", shards.front().file);
    const std::vector<std::string> missing = missingRanges(shards, total);
    if (!missing.empty() && !options.allowMissing)
        throw InputError("vkrt merge: samples " + joined(missing, ", ") + " of " + std::to_string(total) +
                         " are in no shard given (merge them too, or pass --allow-missing)");
    const std::vector<std::string>& firstLayers = shards.front().header.layers;
    const bool shardsHaveVariance = std::count(firstLayers.begin(), firstLayers.end(), "variance") != 0;
    std::vector<Tally> tallies = readTallies(shards);
    int64_t spp = 0;
    for (const Shard& s : shards) spp += s.end - s.begin;
    const Tally merged = mergeTallies(tallies);
    std::map<std::string, Image> layers;
    addTallyLayers(merged, layers);
    const std::optional<Image> variance = tallyVarianceOfMean(merged);
    if (variance && (options.variance || shardsHaveVariance)) layers["variance"] = *variance;
    Metadata metadata = mergedMetadata(shards, spp, missing);
    writeExr(options.output, tallyMean(merged), metadata, layers);
    std::fprintf(stderr, "merged %zu shards, %lld of %lld spp%s -> %s\n", shards.size(), static_cast<long long>(spp),
                 static_cast<long long>(total),
                 missing.empty() ? "" : (" (missing " + joined(missing, ", ") + ")").c_str(), options.output.c_str());
    return Outcome::passed();
}

} // namespace

CommandRunner addMergeCommand(CLI::App& app)
{
    auto o = std::make_shared<MergeOptions>();
    CLI::App* cmd = app.add_subcommand("merge", "Add the shards of one render (vkrt render --shard i/n) into one EXR");
    cmd->add_option("shards", o->shards, "Shard EXRs")->required();
    cmd->add_option("-o,--output", o->output, "Merged EXR")->required();
    cmd->add_flag("--allow-missing", o->allowMissing,
                  "Merge although some sample ranges are in no shard (the result says which, and its true spp)");
    cmd->add_flag("--variance", o->variance, "Write the variance layer even when the shards have none of their own");
    return [o] { return exitCodeFor(runMerge(*o)); };
}

} // namespace vkrt
