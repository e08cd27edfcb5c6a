#pragma once
// Float32 OpenEXR files with vkrt's metadata. The main image is the R, G, B
// channels; extra layers (e.g. "variance") are stored as layer.R/G/B.
#include "io/Image.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace vkrt {

/// A header attribute: text, integer (stored as int when it fits, else double) or real.
using MetadataValue = std::variant<std::string, int64_t, double>;
using Metadata = std::map<std::string, MetadataValue>;

/// Channels in other conventions than a layer's R, G, B: compositors' AOVs
/// such as "N.X", "N.Y", "N.Z" or a lone "Z". `values` holds names.size()
/// floats per pixel, pixel-major.
struct ExrChannels {
    std::vector<std::string> names;
    std::vector<float> values;
};

struct ExrContents {
    Image image;
    std::map<std::string, Image> layers; ///< extra layers by name
    /// Every other channel, grouped by layer ("N" holds N.X, N.Y, N.Z in the
    /// file's order; a channel without a layer, such as "Z", is its own group).
    std::map<std::string, ExrChannels> channels;
    Metadata metadata; ///< vkrt's attributes (standard ones omitted)
};

/// Encodes the whole file in memory (ZIP, one part), then writes it with
/// writeBytesAtomically, so a full disk is an InputError naming the path and
/// the old file stays; costs the encoded file's size in memory, once. A path
/// that is /dev/null is neither encoded nor written.
void writeExr(const std::filesystem::path& path, const Image& image, const Metadata& metadata,
              const std::map<std::string, Image>& layers = {}, const std::vector<ExrChannels>& channels = {});

/// A size a caller knows the file must have, and why: `source` ends in a
/// verb, as in "a.exr is" or "the case renders".
struct ExpectedSize {
    uint32_t width = 0;
    uint32_t height = 0;
    std::string source;
};

/// What an EXR's header says, checked (io/ImageHeader.h) without reading pixels.
struct ExrHeader {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<std::string> layers; ///< extra layers by name
    Metadata metadata;
};

/// Reads and checks the header alone: every check of readExr that needs no
/// pixels, so callers can check all their files before reading any.
ExrHeader readExrHeader(const std::filesystem::path& path, const std::optional<ExpectedSize>& expected = {});

/// Reads an EXR written by vkrt or any tool with R, G, B channels; throws
/// InputError naming the path when it is missing, damaged, lacks channels,
/// or its header is refused before any pixel is allocated: larger than
/// SceneLimits allows, longer than the file could hold, or not `expected`.
/// Pixels are read in strips, so a file whose header lies costs memory only
/// for the pixels it really holds.
ExrContents readExr(const std::filesystem::path& path, const std::optional<ExpectedSize>& expected = {});

} // namespace vkrt
