#pragma once
// 8-bit sRGB previews of linear HDR images.
#include "io/Image.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace vkrt {

/// How linear radiance becomes display values (as the viewer's display
/// kernel does, shaders/kernels/display.comp): clamped to [0, 1], or through
/// the ACES filmic curve (Narkowicz's 2015 fit), which rolls highlights off.
enum class ToneCurve { Clamp, Filmic };

/// Linear radiance -> display: scale by 2^exposure, apply the curve, sRGB encode.
uint8_t toneMapToSrgb8(float linear, float exposure, ToneCurve curve = ToneCurve::Clamp);

/// Tone-mapped RGBA8 pixels (alpha 255), rows top to bottom.
std::vector<uint8_t> toneMapImage(const Image& image, float exposure, ToneCurve curve = ToneCurve::Clamp);

/// Writes a PNG atomically; throws InputError naming the path.
void writePng(const std::filesystem::path& path, const Image& image, float exposure,
              ToneCurve curve = ToneCurve::Clamp);

/// Writes already tone-mapped RGBA8 pixels (rows top to bottom) as a PNG, atomically.
void writePngPixels(const std::filesystem::path& path, uint32_t width, uint32_t height,
                    const std::vector<uint8_t>& rgba);

/// Exact sRGB decoding of an 8-bit value to linear.
float srgb8ToLinear(uint8_t value);

/// Reads an 8-bit sRGB PNG as linear RGB; throws InputError naming the path.
Image readPng(const std::filesystem::path& path);

/// Reads a Radiance RGBE (.hdr) file as linear RGB; throws InputError naming the path.
Image readRadianceHdr(const std::filesystem::path& path);

/// Reads .exr or .hdr (linear) or .png (sRGB) by extension; throws InputError naming the path.
Image readRgbImage(const std::filesystem::path& path);

} // namespace vkrt
