#pragma once
// The marker structure of a JPEG file, walked before it is decoded:
// stb_image decodes a file cut short as if its missing data were zeros (an
// 8x8 JPEG with its headers and no scan data gave a black texture and no
// word), so a file that ends before its image data does is refused here.
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace vkrt {

/// True for bytes that start with a JPEG's start-of-image marker (FF D8).
bool isJpeg(std::span<const uint8_t> bytes);

/// Why a JPEG's marker structure is incomplete or damaged (no frame header,
/// no scan, a scan without data, a segment running past the end, no
/// end-of-image marker), or nullopt when it is whole.
std::optional<std::string> jpegStructureProblem(std::span<const uint8_t> bytes);

} // namespace vkrt
