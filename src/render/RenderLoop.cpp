#include "render/RenderLoop.h"

#include <algorithm>
#include <chrono>

namespace vkrt {

namespace {

constexpr double kTargetSubmitSeconds = 0.25;
constexpr uint32_t kMaxFramesPerSubmit = 64;

bool interrupted(const StopRules& rules) { return rules.interrupt && rules.interrupt->load(); }

/// Frames for the next submission so that it takes about kTargetSubmitSeconds.
uint32_t nextBatch(uint32_t batch, double seconds)
{
    if (seconds <= 0.0) return std::min(batch * 2, kMaxFramesPerSubmit);
    double scaled = double(batch) * kTargetSubmitSeconds / seconds;
    return uint32_t(std::clamp(scaled, 1.0, double(std::min(batch * 2, kMaxFramesPerSubmit))));
}

} // namespace

std::string stopReasonName(StopReason reason)
{
    return reason == StopReason::Interrupted ? "interrupted" : "spp";
}

LoopResult runRenderLoop(Renderer& renderer, const StopRules& rules,
                         const std::function<void(uint32_t)>& onProgress)
{
    using Clock = std::chrono::steady_clock;
    LoopResult result;
    uint32_t batch = 1;
    auto start = Clock::now();
    while (renderer.completedFrames() < rules.spp) {
        if (interrupted(rules)) {
            result.reason = StopReason::Interrupted;
            break;
        }
        uint32_t frames = std::min(batch, rules.spp - renderer.completedFrames());
        auto before = Clock::now();
        renderer.renderFrames(frames);
        batch = nextBatch(batch, std::chrono::duration<double>(Clock::now() - before).count());
        if (onProgress) onProgress(renderer.completedFrames());
    }
    result.renderSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

} // namespace vkrt
