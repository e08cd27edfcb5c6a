#pragma once
// Float32 OpenEXR files with vkrt's metadata. The main image is the R, G, B
// channels; extra layers (e.g. "variance") are stored as layer.R/G/B.
#include "io/Image.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace vkrt {

/// A header attribute: text, integer (stored as int when it fits, else double) or real.
using MetadataValue = std::variant<std::string, int64_t, double>;
using Metadata = std::map<std::string, MetadataValue>;

struct ExrContents {
    Image image;
    std::map<std::string, Image> layers; ///< extra layers by name
    Metadata metadata;                   ///< vkrt's attributes (standard ones omitted)
};

/// Writes atomically (temporary file + rename); throws InputError naming the path.
void writeExr(const std::filesystem::path& path, const Image& image, const Metadata& metadata,
              const std::map<std::string, Image>& layers = {});

/// Reads an EXR written by vkrt or any tool with R, G, B channels; throws
/// InputError naming the path when it is missing, damaged or lacks channels.
ExrContents readExr(const std::filesystem::path& path);

} // namespace vkrt
