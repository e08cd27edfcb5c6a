#include "render/Progress.h"

#include <cmath>
#include <cstdio>

namespace vkrt {

std::string humanCount(double value)
{
    const char* units[] = {"", " k", " M", " G", " T"};
    int unit = 0;
    while (std::abs(value) >= 1000.0 && unit < 4) {
        value /= 1000.0;
        ++unit;
    }
    char text[32];
    std::snprintf(text, sizeof text, "%.3g%s", value, units[unit]);
    return text;
}

Progress::Progress(uint32_t totalFrames, uint64_t pixelsPerFrame, bool interactive)
    : m_total(totalFrames),
      m_pixels(pixelsPerFrame),
      m_interactive(interactive)
{
}

double Progress::elapsedSeconds() const
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
}

double Progress::samplesPerSecond(uint32_t framesDone) const
{
    double seconds = elapsedSeconds();
    return seconds > 0.0 ? double(framesDone) * double(m_pixels) / seconds : 0.0;
}

std::string Progress::formatBar(uint32_t done, uint32_t total, double samplesPerSecond, double etaSeconds)
{
    constexpr int kWidth = 30;
    int filled = total ? int(double(kWidth) * done / total) : kWidth;
    std::string bar = "[" + std::string(filled, '#') + std::string(kWidth - filled, ' ') + "]";
    char text[160];
    std::snprintf(text, sizeof text, "%s %3d%% %u/%u spp  %ssamples/s  ETA %.0fs", bar.c_str(),
                  total ? int(100.0 * done / total) : 100, done, total, humanCount(samplesPerSecond).c_str(),
                  etaSeconds);
    return text;
}

void Progress::update(uint32_t framesDone)
{
    if (!m_interactive) return;
    double seconds = elapsedSeconds();
    double eta = framesDone ? seconds * (m_total - framesDone) / framesDone : 0.0;
    std::fprintf(stderr, "\r%s", formatBar(framesDone, m_total, samplesPerSecond(framesDone), eta).c_str());
    std::fflush(stderr);
}

void Progress::finish()
{
    if (m_interactive) std::fprintf(stderr, "\r\033[K");
}

} // namespace vkrt
