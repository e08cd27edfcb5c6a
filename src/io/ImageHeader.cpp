#include "io/ImageHeader.h"

#include "io/Image.h"
#include "io/RadianceHdr.h"
#include "util/Error.h"

#include <ImfChannelList.h>
#include <ImfStdIO.h>
#include <ImfTileDescriptionAttribute.h>
#include <ImfVersion.h>

// stb_image's implementation is compiled once, in the system's libstb (the `stb` target).
#include <stb/stb_image.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace vkrt {

namespace fs = std::filesystem;

namespace {

/// OpenEXR's limit on attribute and type names (with long names).
constexpr size_t kMaxExrNameLength = 255;
/// Tiles may exceed a small image, but never by more than this a side.
constexpr int kMaxTileSideBeyondImage = 256;

std::string readExrName(Imf::IStream& stream, const std::string& name)
{
    std::string text;
    for (char c = 0; stream.read(&c, 1), c != 0;) {
        text += c;
        if (text.size() > kMaxExrNameLength) failInFile(name, "not a readable EXR file: a header name is too long");
    }
    return text;
}

int32_t readLittleEndianInt(Imf::IStream& stream)
{
    unsigned char bytes[4];
    stream.read(reinterpret_cast<char*>(bytes), 4);
    return int32_t(uint32_t(bytes[0]) | uint32_t(bytes[1]) << 8 | uint32_t(bytes[2]) << 16 | uint32_t(bytes[3]) << 24);
}

/// Walks one header's attributes without reading their values (OpenEXR
/// allocates a value's declared size before reading it); returns how many.
int skipExrAttributes(Imf::IStream& stream, uint64_t streamBytes, const std::string& name)
{
    int count = 0;
    for (std::string attribute = readExrName(stream, name); !attribute.empty(); attribute = readExrName(stream, name)) {
        readExrName(stream, name); // its type
        const int64_t size = readLittleEndianInt(stream);
        const uint64_t end = stream.tellg() + uint64_t(std::max<int64_t>(size, 0));
        if (size < 0 || end > streamBytes)
            failInFile(name, "not a readable EXR file: header attribute '" + attribute + "' declares " +
                                 std::to_string(size) + " bytes, but the file has " + std::to_string(streamBytes));
        stream.seekg(end);
        ++count;
    }
    return count;
}

/// Every header's attributes fit in the file; returns where the headers end.
uint64_t checkExrAttributeSizes(Imf::IStream& stream, uint64_t streamBytes, int version, const std::string& name)
{
    if (Imf::isMultiPart(version))
        while (skipExrAttributes(stream, streamBytes, name) > 0) {
        }
    else skipExrAttributes(stream, streamBytes, name);
    return stream.tellg();
}

int exrLinesPerChunk(Imf::Compression compression)
{
    switch (compression) {
    case Imf::NO_COMPRESSION:
    case Imf::RLE_COMPRESSION:
    case Imf::ZIPS_COMPRESSION: return 1;
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 16;
    case Imf::DWAB_COMPRESSION: return 256;
    default: return 32; // PIZ, B44, B44A, DWAA; fewer chunks is the conservative guess
    }
}

const char* exrCompressionName(Imf::Compression compression)
{
    static const char* const kNames[] = {"none", "RLE", "ZIPS", "ZIP", "PIZ", "PXR24", "B44", "B44A", "DWAA", "DWAB"};
    const auto index = size_t(compression);
    return index < std::size(kNames) ? kNames[index] : "unknown";
}

void checkExrExtent(const Imf::Header& header, const std::string& name)
{
    const Imath::Box2i window = header.dataWindow();
    const int64_t width = int64_t(window.max.x) - window.min.x + 1, height = int64_t(window.max.y) - window.min.y + 1;
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    if (width < 1 || height < 1) failInFile(name, "the header declares an empty data window (" + size + ")");
    if (width > ImageLimits::maxSide || height > ImageLimits::maxSide)
        failInFile(name, "the header declares " + size + " pixels; vkrt reads images of at most " +
                             std::to_string(ImageLimits::maxSide) + " pixels a side");
    if (uint64_t(width * height) > ImageLimits::maxPixels)
        failInFile(name, "the header declares " + size + " pixels; vkrt reads images of at most " +
                             std::to_string(ImageLimits::maxPixels) + " pixels");
}

size_t channelCount(const Imf::Header& header)
{
    size_t count = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) ++count;
    return count;
}

/// Decoded bytes of every channel of the data window (subsampled channels count their samples).
uint64_t exrPixelBytes(const Imf::Header& header)
{
    const ImageExtent extent = extentOf(header);
    uint64_t bytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        const Imf::Channel& channel = it.channel();
        const uint64_t typeBytes = channel.type == Imf::HALF ? 2 : 4;
        const uint64_t xs = uint64_t(std::max(channel.xSampling, 1)), ys = uint64_t(std::max(channel.ySampling, 1));
        bytes += (extent.width / xs) * (extent.height / ys) * typeBytes;
    }
    return bytes;
}

/// Chunks (scan-line blocks or level-0 tiles) and each one's header bytes.
std::pair<uint64_t, uint64_t> exrChunks(const Imf::Header& header, const std::string& name)
{
    const ImageExtent extent = extentOf(header);
    if (!header.hasTileDescription()) {
        const uint64_t lines = uint64_t(exrLinesPerChunk(header.compression()));
        return {(extent.height + lines - 1) / lines, 8}; // y, byte count
    }
    const Imf::TileDescription& tiles = header.tileDescription();
    if (tiles.xSize < 1 || tiles.ySize < 1 || tiles.xSize > std::max<uint64_t>(extent.width, kMaxTileSideBeyondImage) ||
        tiles.ySize > std::max<uint64_t>(extent.height, kMaxTileSideBeyondImage))
        failInFile(name, "the header declares " + std::to_string(tiles.xSize) + "x" + std::to_string(tiles.ySize) +
                             " tiles for a " + extent.str() + " image");
    const uint64_t across = (extent.width + tiles.xSize - 1) / tiles.xSize;
    const uint64_t down = (extent.height + tiles.ySize - 1) / tiles.ySize;
    return {across * down, 20}; // x, y, level x, level y, byte count
}

/// The file must hold the offset table, every chunk's header, and the pixels at the best compression possible.
void checkExrLength(const Imf::Header& header, uint64_t headerEnd, uint64_t streamBytes, const std::string& name)
{
    const auto [chunks, chunkHeaderBytes] = exrChunks(header, name);
    const uint64_t pixelBytes = exrPixelBytes(header);
    const uint64_t ratio = exrMaxCompressionRatio(header.compression());
    const uint64_t smallest = headerEnd + chunks * (8 + chunkHeaderBytes) + (pixelBytes + ratio - 1) / ratio;
    if (streamBytes < smallest)
        failInFile(name, "the header declares " + extentOf(header).str() + " pixels of " +
                             std::to_string(channelCount(header)) + " channels (" +
                             exrCompressionName(header.compression()) + " compression), which take at least " +
                             std::to_string(smallest) + " bytes, but the file has " + std::to_string(streamBytes) +
                             ": truncated or damaged");
}

bool fileStartsWithRadianceSignature(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    uint8_t head[2] = {0, 0};
    in.read(reinterpret_cast<char*>(head), 2);
    return in.gcount() == 2 && isRadianceHdr(head);
}

} // namespace

uint64_t exrMaxCompressionRatio(Imf::Compression compression)
{
    switch (compression) {
    case Imf::NO_COMPRESSION: return 1;
    case Imf::RLE_COMPRESSION: return 128;
    case Imf::ZIPS_COMPRESSION:
    case Imf::ZIP_COMPRESSION:
    case Imf::PIZ_COMPRESSION:
    case Imf::PXR24_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION: return 2048;
    default: return uint64_t(1) << 18; // DWAA, DWAB (DCT) and compressions newer than this list
    }
}

ImageExtent extentOf(const Imf::Header& header)
{
    const Imath::Box2i window = header.dataWindow();
    return {uint32_t(int64_t(window.max.x) - window.min.x + 1), uint32_t(int64_t(window.max.y) - window.min.y + 1)};
}

Imf::Header readCheckedExrHeader(Imf::IStream& stream, uint64_t streamBytes, const std::string& name)
{
    try {
        stream.seekg(0);
        unsigned char magic[4];
        stream.read(reinterpret_cast<char*>(magic), 4);
        int version = readLittleEndianInt(stream);
        if (!Imf::isImfMagic(reinterpret_cast<const char*>(magic)))
            failInFile(name, "not a readable EXR file: no OpenEXR signature");
        if (Imf::isNonImage(version)) failInFile(name, "deep EXR images are not supported");
        const uint64_t headerEnd = checkExrAttributeSizes(stream, streamBytes, version, name);
        stream.seekg(8);
        Imf::Header header;
        header.readFrom(stream, version);
        header.sanityCheck(Imf::isTiled(version) || header.hasTileDescription(), Imf::isMultiPart(version));
        checkExrExtent(header, name);
        checkExrLength(header, headerEnd, streamBytes, name);
        return header;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        failInFile(name, std::string("not a readable EXR file: ") + e.what());
    }
}

MemoryExrStream::MemoryExrStream(std::span<const uint8_t> bytes, const std::string& name)
    : Imf::IStream(name.c_str()),
      m_bytes(bytes)
{
}

bool MemoryExrStream::read(char c[], int n)
{
    if (n < 0 || m_position + uint64_t(n) > m_bytes.size()) throw std::runtime_error("unexpected end of data");
    std::memcpy(c, m_bytes.data() + m_position, size_t(n));
    m_position += uint64_t(n);
    return m_position < m_bytes.size();
}

ImageExtent stbImageExtent(std::span<const uint8_t> bytes, const std::string& name)
{
    if (isRadianceHdr(bytes)) return radianceHdrExtent(bytes, bytes.size(), name);
    if (bytes.size() > size_t(INT_MAX)) failInFile(name, "unsupported image: larger than 2 GiB");
    int width = 0, height = 0, channels = 0;
    if (!stbi_info_from_memory(bytes.data(), int(bytes.size()), &width, &height, &channels))
        failInFile(name, std::string("no image header stb_image can read (stb_image: ") +
                             (stbi_failure_reason() ? stbi_failure_reason() : "unknown reason") + ")");
    return {uint32_t(width), uint32_t(height)};
}

ImageExtent stbImageFileExtent(const fs::path& file)
{
    if (fileStartsWithRadianceSignature(file)) return radianceHdrFileExtent(file);
    int width = 0, height = 0, channels = 0;
    if (!stbi_info(file.c_str(), &width, &height, &channels))
        failInFile(file.string(), std::string("no image header stb_image can read (stb_image: ") +
                                      (stbi_failure_reason() ? stbi_failure_reason() : "unknown reason") + ")");
    return {uint32_t(width), uint32_t(height)};
}

ImageExtent imageFileExtent(const fs::path& file)
{
    std::error_code error;
    const fs::file_status status = fs::status(file, error);
    if (!fs::exists(status)) failInFile(file.string(), "no such file");
    if (!fs::is_regular_file(status)) failInFile(file.string(), "is not a regular file");
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension != ".exr") return stbImageFileExtent(file);
    try {
        Imf::StdIFStream stream(file.c_str());
        return extentOf(readCheckedExrHeader(stream, fs::file_size(file), file.string()));
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        failInFile(file.string(), std::string("not a readable EXR file: ") + e.what());
    }
}

} // namespace vkrt
