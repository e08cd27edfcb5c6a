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
#include "render/Tally.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
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

const MetadataValue& required(const ExrContents& exr, const std::string& key, const std::string& file)
{
    const auto found = exr.metadata.find(key);
    if (found == exr.metadata.end())
        throw InputError(file + ": no '" + key + "' attribute: not a shard written by `vkrt render --shard`");
    return found->second;
}

int64_t integer(const ExrContents& exr, const std::string& key, const std::string& file)
{
    const auto* value = std::get_if<int64_t>(&required(exr, key, file));
    if (!value) throw InputError(file + ": attribute '" + key + "' is not an integer");
    return *value;
}

struct Shard {
    std::string file;
    ExrContents exr;
    int64_t begin = 0, end = 0;
    bool interrupted = false;
};

Shard readShard(const std::string& file)
{
    Shard shard{file, readExr(file)};
    required(shard.exr, "shard", file);
    shard.begin = integer(shard.exr, "sampleBegin", file);
    shard.end = integer(shard.exr, "sampleEnd", file);
    if (shard.begin < 0 || shard.end <= shard.begin)
        throw InputError(file + ": sample range [" + std::to_string(shard.begin) + ", " + std::to_string(shard.end) +
                         ") is empty or negative");
    const auto stopped = shard.exr.metadata.find("stoppedBy");
    shard.interrupted = stopped != shard.exr.metadata.end() && text(stopped->second) == "interrupted";
    return shard;
}

/// Every shard like the first (naming the odd one), and no two ranges overlapping.
void checkTheyBelongTogether(const std::vector<Shard>& shards)
{
    const Shard& first = shards.front();
    for (const Shard& s : shards) {
        if (s.exr.image.width != first.exr.image.width || s.exr.image.height != first.exr.image.height)
            throw InputError(s.file + ": " + std::to_string(s.exr.image.width) + "x" +
                             std::to_string(s.exr.image.height) + ", but " + first.file + " is " +
                             std::to_string(first.exr.image.width) + "x" + std::to_string(first.exr.image.height));
        for (const char* key : kSharedKeys) {
            const std::string mine = text(required(s.exr, key, s.file)),
                              theirs = text(required(first.exr, key, first.file));
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
    Metadata metadata = shards.front().exr.metadata;
    for (const char* key :
         {"shard", "stoppedBy", "estimatedRmse", "estimatedRelMse", "renderSeconds", "device", "driver", "savedBy"})
        metadata.erase(key);
    double seconds = 0.0, rejected = 0.0;
    std::vector<std::string> files, interrupted;
    for (const Shard& s : shards) {
        if (const auto* t = std::get_if<double>(&s.exr.metadata.at("renderSeconds"))) seconds += *t;
        if (const auto found = s.exr.metadata.find("rejectedSamples"); found != s.exr.metadata.end())
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

/// Before reading anything: `-o` must not be one of the shards (it would be destroyed) and must be writable.
void checkMergeFiles(const MergeOptions& options)
{
    std::vector<NamedFile> inputs;
    for (const std::string& file : options.shards) inputs.push_back({"shard", file});
    checkOutputs(inputs, {{"-o", options.output}});
}

int runMerge(const MergeOptions& options)
{
    checkMergeFiles(options);
    std::vector<Shard> shards;
    for (const std::string& file : options.shards) shards.push_back(readShard(file));
    checkTheyBelongTogether(shards);
    const int64_t total = integer(shards.front().exr, "totalSpp", shards.front().file);
    const std::vector<std::string> missing = missingRanges(shards, total);
    if (!missing.empty() && !options.allowMissing)
        throw InputError("vkrt merge: samples " + joined(missing, ", ") + " of " + std::to_string(total) +
                         " are in no shard given (merge them too, or pass --allow-missing)");
    const bool shardsHaveVariance = shards.front().exr.layers.count("variance") != 0;
    std::vector<Tally> tallies;
    int64_t spp = 0;
    for (Shard& s : shards) {
        tallies.push_back(readTally(s.exr, s.file));
        spp += s.end - s.begin;
        s.exr.layers.clear(); // only the tally is needed from here on: a 4K shard's layers are ~0.5 GB
        s.exr.image = Image();
    }
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
    return kExitOk;
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
    return [o] { return runMerge(*o); };
}

} // namespace vkrt
