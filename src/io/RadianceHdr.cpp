#include "io/RadianceHdr.h"

#include "io/Image.h"
#include "util/Error.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string_view>

namespace vkrt {

namespace {

/// A header longer than this is no image header (real ones are a few hundred bytes).
constexpr size_t kMaxHeaderBytes = 64 * 1024;
/// Adaptive RLE is defined for scanlines of 8 to 32767 pixels; others are flat.
constexpr uint32_t kMinRleWidth = 8, kMaxRleWidth = 32767;
/// A run repeats one byte at most 127 times (its count byte is 128 + n).
constexpr uint64_t kLongestRun = 127;

struct Header {
    ImageExtent extent;
    size_t dataOffset = 0;
};

/// The next line (without its '\n') from `at`; fails when the header has no end.
std::string_view nextLine(std::span<const uint8_t> bytes, size_t& at, const std::string& name)
{
    const auto* begin = reinterpret_cast<const char*>(bytes.data());
    const size_t limit = std::min(bytes.size(), kMaxHeaderBytes);
    for (size_t end = at; end < limit; ++end) {
        if (begin[end] != '\n') continue;
        const std::string_view line(begin + at, end - at);
        at = end + 1;
        return line;
    }
    if (bytes.size() > kMaxHeaderBytes)
        failInFile(name, "not a readable Radiance HDR file: no end of header within " +
                             std::to_string(kMaxHeaderBytes) + " bytes");
    failInFile(name, "not a readable Radiance HDR file: the header ends before its resolution line");
}

/// A decimal count of at most 9 digits (the limits check it further).
bool parseCount(std::string_view text, uint32_t& value)
{
    if (text.empty() || text.size() > 9) return false;
    value = 0;
    for (const char c : text) {
        if (c < '0' || c > '9') return false;
        value = value * 10 + uint32_t(c - '0');
    }
    return true;
}

/// "-Y H +X W": rows top to bottom, pixels left to right.
ImageExtent parseResolution(std::string_view line, const std::string& name)
{
    const std::string shown(line.substr(0, 64));
    auto token = [&](std::string_view& rest) {
        const size_t start = rest.find_first_not_of(' ');
        if (start == std::string_view::npos) return std::string_view();
        rest.remove_prefix(start);
        const size_t end = std::min(rest.find(' '), rest.size());
        const std::string_view t = rest.substr(0, end);
        rest.remove_prefix(end);
        return t;
    };
    std::string_view rest = line;
    const std::string_view yAxis = token(rest), heightText = token(rest), xAxis = token(rest), widthText = token(rest);
    if (!token(rest).empty() || (yAxis != "-Y" && yAxis != "+Y" && yAxis != "-X" && yAxis != "+X"))
        failInFile(name, "not a readable Radiance HDR file: the resolution line '" + shown + "' is not '-Y H +X W'");
    if (yAxis != "-Y" || xAxis != "+X")
        failInFile(name,
                   "unsupported Radiance HDR orientation '" + shown + "': vkrt reads '-Y H +X W' (top row first)");
    ImageExtent extent;
    if (!parseCount(heightText, extent.height) || !parseCount(widthText, extent.width))
        failInFile(name, "not a readable Radiance HDR file: the resolution line '" + shown + "' has no size");
    const std::string size = extent.str();
    if (extent.width == 0 || extent.height == 0) failInFile(name, "the header declares an empty image (" + size + ")");
    if (extent.width > ImageLimits::maxSide || extent.height > ImageLimits::maxSide)
        failInFile(name, "the header declares " + size + " pixels; vkrt reads images of at most " +
                             std::to_string(ImageLimits::maxSide) + " pixels a side");
    if (extent.pixels() > ImageLimits::maxPixels)
        failInFile(name, "the header declares " + size + " pixels; vkrt reads images of at most " +
                             std::to_string(ImageLimits::maxPixels) + " pixels");
    return extent;
}

bool rleWidth(uint32_t width) { return width >= kMinRleWidth && width <= kMaxRleWidth; }

/// The fewest bytes a scanline of `width` pixels can take: flat, or every
/// channel in runs of the longest length.
uint64_t smallestScanline(uint32_t width)
{
    const uint64_t flat = 4ull * width;
    if (!rleWidth(width)) return flat;
    return std::min(flat, 4 + 4 * 2 * ((width + kLongestRun - 1) / kLongestRun));
}

/// The header from the file's first bytes (all of them, or at least the
/// header's), checked against the file's length `fileBytes`.
Header readHeader(std::span<const uint8_t> bytes, uint64_t fileBytes, const std::string& name)
{
    if (!isRadianceHdr(bytes)) failInFile(name, "not a Radiance HDR file: no '#?' signature");
    size_t at = 0;
    const std::string_view signature = nextLine(bytes, at, name);
    if (!signature.starts_with("#?RADIANCE") && !signature.starts_with("#?RGBE"))
        failInFile(name, "not a readable Radiance HDR file: the signature is '" + std::string(signature.substr(0, 32)) +
                             "', not #?RADIANCE or #?RGBE");
    for (std::string_view line = nextLine(bytes, at, name); !line.empty(); line = nextLine(bytes, at, name)) {
        if (!line.starts_with("FORMAT=")) continue;
        const std::string_view format = line.substr(7);
        if (format == "32-bit_rle_xyze") failInFile(name, "unsupported Radiance HDR format 32-bit_rle_xyze (CIE XYZ)");
        if (format != "32-bit_rle_rgbe")
            failInFile(name, "unsupported Radiance HDR format '" + std::string(format.substr(0, 32)) + "'");
    }
    Header header;
    header.extent = parseResolution(nextLine(bytes, at, name), name);
    header.dataOffset = at;
    const uint64_t smallest = at + header.extent.height * smallestScanline(header.extent.width);
    if (fileBytes < smallest)
        failInFile(name, "the header declares " + header.extent.str() + " pixels, which take at least " +
                             std::to_string(smallest) + " bytes, but the file has " + std::to_string(fileBytes) +
                             ": truncated or damaged");
    return header;
}

/// Reads scanlines into RGBE quadruples, failing with the scanline's number.
class ScanlineReader {
public:
    ScanlineReader(std::span<const uint8_t> bytes, size_t at, const std::string& name)
        : m_bytes(bytes),
          m_at(at),
          m_name(name)
    {
    }

    void read(uint32_t y, uint32_t width, uint8_t* rgbe)
    {
        m_y = y;
        if (rleWidth(width) && has(4) && m_bytes[m_at] == 2 && m_bytes[m_at + 1] == 2 && !(m_bytes[m_at + 2] & 0x80))
            return readRunLength(width, rgbe);
        if (has(4) && m_bytes[m_at] == 1 && m_bytes[m_at + 1] == 1 && m_bytes[m_at + 2] == 1)
            bad("uses the old-style run-length encoding, which vkrt does not read");
        need(4ull * width, "its pixels");
        std::copy_n(m_bytes.begin() + std::ptrdiff_t(m_at), 4ull * width, rgbe);
        m_at += 4ull * width;
    }

private:
    bool has(uint64_t count) const { return m_bytes.size() - m_at >= count; }

    [[noreturn]] void bad(const std::string& what) const
    {
        failInFile(m_name, "truncated or damaged Radiance HDR: scanline " + std::to_string(m_y) + " " + what);
    }

    void need(uint64_t count, const char* what) const
    {
        if (!has(count))
            bad(std::string("ends before ") + what + " (the file has " + std::to_string(m_bytes.size()) + " bytes)");
    }

    void readRunLength(uint32_t width, uint8_t* rgbe)
    {
        const uint32_t declared = uint32_t(m_bytes[m_at + 2]) << 8 | m_bytes[m_at + 3];
        if (declared != width)
            bad("declares " + std::to_string(declared) + " pixels, the header " + std::to_string(width));
        m_at += 4;
        for (uint32_t channel = 0; channel < 4; ++channel) {
            for (uint32_t x = 0; x < width;) {
                need(1, "its runs");
                const uint32_t count = m_bytes[m_at++];
                const bool repeated = count > 128;
                const uint32_t length = repeated ? count - 128 : count;
                if (length == 0) bad("has a run of length 0");
                if (length > width - x)
                    bad("has a run of " + std::to_string(length) + " past its end (" + std::to_string(width - x) +
                        " pixels left in channel " + std::to_string(channel) + ")");
                need(repeated ? 1 : length, "its runs");
                for (uint32_t i = 0; i < length; ++i)
                    rgbe[4 * (x + i) + channel] = repeated ? m_bytes[m_at] : m_bytes[m_at + i];
                m_at += repeated ? 1 : length;
                x += length;
            }
        }
    }

    std::span<const uint8_t> m_bytes;
    size_t m_at;
    const std::string& m_name;
    uint32_t m_y = 0;
};

} // namespace

bool isRadianceHdr(std::span<const uint8_t> bytes) { return bytes.size() >= 2 && bytes[0] == '#' && bytes[1] == '?'; }

ImageExtent radianceHdrExtent(std::span<const uint8_t> bytes, uint64_t fileBytes, const std::string& name)
{
    return readHeader(bytes, fileBytes, name).extent;
}

ImageExtent radianceHdrFileExtent(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) failInFile(file.string(), "cannot be opened");
    std::vector<uint8_t> head(kMaxHeaderBytes + 1);
    in.read(reinterpret_cast<char*>(head.data()), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    return radianceHdrExtent(head, std::filesystem::file_size(file), file.string());
}

RadianceHdrImage decodeRadianceHdr(std::span<const uint8_t> bytes, const std::string& name)
{
    const Header header = readHeader(bytes, bytes.size(), name);
    const uint32_t width = header.extent.width;
    RadianceHdrImage image{header.extent, std::vector<float>(header.extent.pixels() * 4)};
    std::vector<uint8_t> rgbe(4ull * width);
    ScanlineReader reader(bytes, header.dataOffset, name);
    for (uint32_t y = 0; y < header.extent.height; ++y) {
        reader.read(y, width, rgbe.data());
        float* row = image.rgba.data() + 4ull * width * y;
        for (uint32_t x = 0; x < width; ++x) {
            const uint8_t* p = &rgbe[4 * x];
            // RGBE: mantissas over a shared exponent, 0 for black (as stb_image decoded it).
            const float scale = p[3] == 0 ? 0.0f : std::ldexp(1.0f, int(p[3]) - (128 + 8));
            row[4 * x + 0] = float(p[0]) * scale;
            row[4 * x + 1] = float(p[1]) * scale;
            row[4 * x + 2] = float(p[2]) * scale;
            row[4 * x + 3] = 1.0f;
        }
    }
    return image;
}

} // namespace vkrt
