#pragma once
// Render progress on stderr: a live bar with samples/s and ETA on a terminal,
// nothing until the end otherwise (logs stay clean).
#include <chrono>
#include <cstdint>
#include <string>

namespace vkrt {

class Progress {
public:
    Progress(uint32_t totalFrames, uint64_t pixelsPerFrame, bool interactive);
    /// Reports that `framesDone` frames are finished.
    void update(uint32_t framesDone);
    /// Clears the bar (interactive only).
    void finish();
    double elapsedSeconds() const;
    double samplesPerSecond(uint32_t framesDone) const;

    /// "[#####     ] 50% 32/64 spp  1.2 Msamples/s  ETA 3s"
    static std::string formatBar(uint32_t done, uint32_t total, double samplesPerSecond, double etaSeconds);

private:
    uint32_t m_total;
    uint64_t m_pixels;
    bool m_interactive;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
};

/// 1234567 -> "1.23 M"
std::string humanCount(double value);

} // namespace vkrt
