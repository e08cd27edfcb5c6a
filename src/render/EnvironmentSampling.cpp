#include "render/EnvironmentSampling.h"

#include <cmath>

namespace vkrt {

std::vector<float> environmentCdf(const std::array<Image, 6>& faces)
{
    const uint32_t n = faces[0].width;
    std::vector<double> weights;
    weights.reserve(6 * size_t(n) * n);
    for (const Image& face : faces) {
        for (uint32_t y = 0; y < n; ++y) {
            for (uint32_t x = 0; x < n; ++x) {
                const float* t = face.at(x, y);
                double luminance = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
                double sc = 2.0 * (x + 0.5) / n - 1.0, tc = 2.0 * (y + 0.5) / n - 1.0;
                double r = std::sqrt(sc * sc + tc * tc + 1.0);
                weights.push_back(std::max(0.0, luminance) / (r * r * r));
            }
        }
    }
    double total = 0.0;
    for (double w : weights) total += w;
    if (!(total > 0.0)) {
        weights.assign(weights.size(), 1.0);
        total = double(weights.size());
    }
    std::vector<float> cdf(weights.size() + 1, 0.0f);
    double running = 0.0;
    for (size_t i = 0; i < weights.size(); ++i) {
        running += weights[i];
        cdf[i + 1] = float(running / total);
    }
    cdf.back() = 1.0f;
    return cdf;
}

} // namespace vkrt
