#include "render/RenderLoop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vkrt {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kTargetSubmitSeconds = 0.25;
constexpr uint32_t kMaxFramesPerSubmit = 64;

bool interrupted(const StopRules& rules) { return rules.interrupt && rules.interrupt->load(); }

/// Frames for the next submission: about kTargetSubmitSeconds of work, never
/// past the next checkpoint or the spp limit, and never (by the measured
/// frame time) past the time budget.
uint32_t framesForNextBatch(uint32_t batch, uint32_t done, uint32_t checkpoint, const StopRules& rules, double elapsed,
                            double secondsPerFrame)
{
    uint32_t frames = std::min({batch, rules.maxSpp - done, checkpoint - done});
    if (rules.timeBudgetSeconds && secondsPerFrame > 0.0) {
        // Spend half the remaining time per batch, and go one frame at a time
        // at the end, so that a slow frame overshoots the budget by itself only.
        double affordable = std::floor(0.5 * (*rules.timeBudgetSeconds - elapsed) / secondsPerFrame);
        frames = std::min<uint32_t>(frames, uint32_t(std::clamp(affordable, 1.0, double(frames))));
    }
    return std::max(frames, 1u);
}

} // namespace

void BatchPacer::record(uint32_t frames, double seconds)
{
    uint32_t most = std::min(frames * 2, kMaxFramesPerSubmit);
    m_frames =
        seconds <= 0.0 ? most : uint32_t(std::clamp(double(frames) * m_targetSeconds / seconds, 1.0, double(most)));
}

uint32_t nextCheckpoint(uint32_t spp)
{
    uint32_t next = 1;
    while (next <= spp && next < (1u << 31)) next *= 2;
    return next;
}

std::optional<uint32_t> sppExpectedToMeet(uint32_t spp, double bound, double target, uint32_t granularity)
{
    if (!std::isfinite(bound) || !(bound > target) || !(target > 0.0) || granularity == 0) return std::nullopt;
    double expected = std::ceil(double(spp) * bound / target * 1.05 / granularity) * granularity;
    double ahead = (double(spp) / granularity + 1.0) * granularity;
    double next = std::min(std::max(expected, ahead), double(1u << 31));
    return uint32_t(next);
}

std::string stopReasonName(StopReason reason)
{
    switch (reason) {
    case StopReason::Interrupted: return "interrupted";
    case StopReason::TimeBudget: return "time-budget";
    case StopReason::TargetError: return "target-error";
    case StopReason::SppReached: break;
    }
    return "spp";
}

LoopResult runRenderLoop(Renderer& renderer, const StopRules& rules, const std::function<void(uint32_t)>& onProgress,
                         const CheckpointHandler& onCheckpoint)
{
    LoopResult result;
    BatchPacer pacer(kTargetSubmitSeconds);
    double secondsPerFrame = 0.0;
    std::optional<uint32_t> requested; // a checkpoint the handler asked for
    while (true) {
        uint32_t done = renderer.completedFrames();
        if (done >= rules.maxSpp) break;
        if (interrupted(rules)) {
            result.reason = StopReason::Interrupted;
            break;
        }
        if (rules.timeBudgetSeconds && result.renderSeconds >= *rules.timeBudgetSeconds) {
            result.reason = StopReason::TimeBudget;
            break;
        }
        uint32_t checkpoint = nextCheckpoint(done);
        if (requested && *requested > done) checkpoint = std::min(checkpoint, *requested);
        uint32_t frames =
            framesForNextBatch(pacer.nextFrames(), done, checkpoint, rules, result.renderSeconds, secondsPerFrame);
        auto start = Clock::now();
        renderer.renderFrames(frames);
        double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        result.renderSeconds += seconds;
        secondsPerFrame = seconds / frames;
        pacer.record(frames, seconds);
        done = renderer.completedFrames();
        if (onProgress) onProgress(done);
        bool atCheckpoint = done == checkpoint || done == rules.maxSpp;
        if (!atCheckpoint || !onCheckpoint) continue;
        CheckpointDecision decision = onCheckpoint(done, result.renderSeconds);
        if (decision.stop) {
            result.reason = StopReason::TargetError;
            break;
        }
        requested = decision.nextSpp;
    }
    return result;
}

} // namespace vkrt
