#pragma once
// Drives a Renderer until a stop rule fires. Frames are batched into
// submissions of about a quarter second (so progress and Ctrl-C stay
// responsive without paying a submission per frame), and batches end exactly
// at the checkpoints 1, 2, 4, 8, ... spp (and where the target-error rule
// expects its target met), where convergence reports and the target-error
// rule look at the image.
#include "render/Renderer.h"

#include <atomic>
#include <functional>
#include <optional>
#include <string>

namespace vkrt {

/// Samples per pixel when a render names none and has no time or error rule.
constexpr uint32_t kDefaultSpp = 64;

/// The spp cap of a render (`--spp`, Python's `spp=`): the one given; else
/// none to speak of (2^30) when a time budget or target error will stop it,
/// else kDefaultSpp.
constexpr uint32_t sppCap(std::optional<uint32_t> spp, bool timeOrErrorRule)
{
    return spp ? *spp : timeOrErrorRule ? (1u << 30) : kDefaultSpp;
}

/// When a render stops: whichever rule fires first.
struct StopRules {
    uint32_t maxSpp = 64;
    std::optional<double> timeBudgetSeconds; ///< of rendering, start-up excluded
    std::optional<double> targetRelMse;      ///< estimated relMSE; the checkpoint handler tests it (it needs the film)
    const std::atomic<bool>* interrupt = nullptr; ///< set asynchronously (SIGINT)
};

enum class StopReason { SppReached, TimeBudget, TargetError, Interrupted };
std::string stopReasonName(StopReason reason);

struct LoopResult {
    StopReason reason = StopReason::SppReached;
    double renderSeconds = 0.0; ///< wall time spent in frames (no compile, set-up or checkpoint work)
};

/// Sizes submissions so that each takes about `targetSeconds`, from the
/// measured time of the last one: at most twice its frames, at most 64.
/// The render loop paces with a quarter second, the viewer with a display refresh.
class BatchPacer {
public:
    explicit BatchPacer(double targetSeconds) : m_targetSeconds(targetSeconds) {}
    uint32_t nextFrames() const { return m_frames; }
    void record(uint32_t frames, double seconds);

private:
    double m_targetSeconds;
    uint32_t m_frames = 1;
};

/// What a checkpoint handler decides: stop (target reached), or go on, with
/// an extra checkpoint at `nextSpp` where it expects the target to be met
/// (one before the next power of two; the loop ignores one not ahead of it).
struct CheckpointDecision {
    bool stop = false;
    std::optional<uint32_t> nextSpp;
};

/// Called at every checkpoint (spp a power of two, one a handler asked for,
/// and the final spp) with the render time so far.
using CheckpointHandler = std::function<CheckpointDecision(uint32_t spp, double renderSeconds)>;

LoopResult runRenderLoop(Renderer& renderer, const StopRules& rules,
                         const std::function<void(uint32_t framesDone)>& onProgress = {},
                         const CheckpointHandler& onCheckpoint = {});

/// The next power of two strictly above `spp`.
uint32_t nextCheckpoint(uint32_t spp);

/// Where an error bound of `bound` at `spp` should fall to `target`: a
/// relMSE falls as 1 / spp, so at spp * bound / target; aimed 5 % past that,
/// rounded up to a multiple of `granularity` (the variance batches, so that
/// they stay equal) and at least one granule ahead. None for a bound that is
/// not finite (no estimate yet) or already at the target.
std::optional<uint32_t> sppExpectedToMeet(uint32_t spp, double bound, double target, uint32_t granularity);

} // namespace vkrt
