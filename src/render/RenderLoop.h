#pragma once
// Drives a Renderer until a stop rule fires, batching frames into submissions
// of about a quarter second so progress and Ctrl-C stay responsive without
// paying a submission per frame.
#include "render/Renderer.h"

#include <atomic>
#include <functional>
#include <string>

namespace vkrt {

struct StopRules {
    uint32_t spp = 64;
    const std::atomic<bool>* interrupt = nullptr; ///< set asynchronously (SIGINT)
};

enum class StopReason { SppReached, Interrupted };
std::string stopReasonName(StopReason reason);

struct LoopResult {
    StopReason reason = StopReason::SppReached;
    double renderSeconds = 0.0; ///< wall time spent in frames (no compile or set-up)
};

LoopResult runRenderLoop(Renderer& renderer, const StopRules& rules,
                         const std::function<void(uint32_t framesDone)>& onProgress = {});

} // namespace vkrt
