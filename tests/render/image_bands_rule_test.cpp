// The band layout rule (render/ImageBands.h), without a device: the fewest
// bands of whole workgroup rows whose largest per-pixel buffer fits the
// device's maxStorageBufferRange, covering every row once.
#include "render/ImageBands.h"
#include "shared/Bindings.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <random>

namespace vkrt {
namespace {

constexpr uint64_t kLavapipeRange = uint64_t(1) << 27; // 128 MiB
constexpr uint64_t kAccumBytes = 28;                   // sizeof(gpu::AccumPixel)

void expectValidLayout(const ImageBands& bands, uint64_t bytesPerPixel, uint64_t maxBytes)
{
    ASSERT_GE(bands.count, 1u);
    uint32_t covered = 0;
    for (uint32_t b = 0; b < bands.count; ++b) {
        EXPECT_EQ(bands.firstRow(b), covered);
        EXPECT_GT(bands.rows(b), 0u);
        EXPECT_LE(uint64_t(bands.rows(b)) * bands.width * bytesPerPixel, maxBytes) << "band " << b;
        covered += bands.rows(b);
    }
    EXPECT_EQ(covered, bands.height);
    if (bands.count == 1) return;
    EXPECT_EQ(bands.rowsPerBand % gpu::WORKGROUP_SIZE_Y, 0u);
    // The fewest bands: one more workgroup row per band would not fit.
    EXPECT_GT(uint64_t(bands.rowsPerBand + gpu::WORKGROUP_SIZE_Y) * bands.width * bytesPerPixel, maxBytes);
}

TEST(ImageBandsRule, AnImageThatFitsIsOneBand)
{
    ImageBands bands = imageBandsFor(1920, 1080, kAccumBytes, kLavapipeRange, "scene.toml");
    EXPECT_EQ(bands.count, 1u);
    EXPECT_EQ(bands.rowsPerBand, 1080u);
    EXPECT_EQ(bands.tileRowsPerBand(), 135u);
    expectValidLayout(bands, kAccumBytes, kLavapipeRange);
}

// The case: 3840 x 2160 needs 0.22 GiB of accumulation, lavapipe
// guarantees 0.125 GiB per storage buffer.
TEST(ImageBandsRule, UltraHdOnLavapipeIsTwoBands)
{
    ImageBands bands = imageBandsFor(3840, 2160, kAccumBytes, kLavapipeRange, "scene.toml");
    EXPECT_EQ(bands.count, 2u);
    EXPECT_EQ(bands.rowsPerBand, 1248u); // 134217728 / (3840 * 28) = 1248.3
    EXPECT_EQ(bands.rows(1), 2160u - 1248u);
    expectValidLayout(bands, kAccumBytes, kLavapipeRange);
    // Eight Sobol' batch sums per pixel (224 bytes): 152 rows a band, 15 bands.
    ImageBands batches = imageBandsFor(3840, 2160, 224, kLavapipeRange, "scene.toml");
    expectValidLayout(batches, 224, kLavapipeRange);
    EXPECT_EQ(batches.count, 15u);
}

TEST(ImageBandsRule, EverySizeIsCoveredByTheFewestFittingBands)
{
    std::mt19937 random(7);
    std::uniform_int_distribution<uint32_t> size(1, 5000);
    std::uniform_int_distribution<uint64_t> range(1 << 16, 1 << 28);
    for (int i = 0; i < 2000; ++i) {
        uint32_t width = size(random), height = size(random);
        uint64_t bytesPerPixel = (i % 3 == 0) ? 28 : (i % 3 == 1) ? 36 : 224;
        uint64_t maxBytes = range(random);
        if (uint64_t(width) * gpu::WORKGROUP_SIZE_Y * bytesPerPixel > maxBytes) continue;
        ImageBands bands = imageBandsFor(width, height, bytesPerPixel, maxBytes, "scene.toml");
        SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + ", " + std::to_string(bytesPerPixel) +
                     " B, range " + std::to_string(maxBytes));
        expectValidLayout(bands, bytesPerPixel, maxBytes);
    }
}

TEST(ImageBandsRule, RefusesAnImageOfWhichNotEvenOneWorkgroupRowFits)
{
    try {
        imageBandsFor(16384, 100, 224, 1 << 20, "wide.toml");
        FAIL() << "expected InputError";
    } catch (const InputError& error) {
        std::string message = error.what();
        EXPECT_NE(message.find("wide.toml"), std::string::npos) << message;
        EXPECT_NE(message.find("--width"), std::string::npos) << message;
        EXPECT_NE(message.find("maxStorageBufferRange"), std::string::npos) << message;
    }
}

} // namespace
} // namespace vkrt
