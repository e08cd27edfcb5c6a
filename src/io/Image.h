#pragma once
// A linear float32 RGB image, rows top to bottom.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vkrt {

/// The largest image vkrt renders or reads (docs/scene-format.md): the scene
/// format's image limits (SceneLimits) are these, and image files whose
/// header declares more are refused before their pixels are allocated.
struct ImageLimits {
    static constexpr uint32_t maxSide = 16384;
    static constexpr uint64_t maxPixels = 64ull * 1024 * 1024;
};

struct Image {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<float> rgb; ///< width * height * 3 floats

    Image() = default;
    Image(uint32_t w, uint32_t h) : width(w), height(h), rgb(std::size_t(w) * h * 3, 0.0f) {}

    std::size_t pixelCount() const { return std::size_t(width) * height; }
    float* at(uint32_t x, uint32_t y) { return &rgb[(std::size_t(y) * width + x) * 3]; }
    const float* at(uint32_t x, uint32_t y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

} // namespace vkrt
