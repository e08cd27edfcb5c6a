#include "texture/JpegStructure.h"

namespace vkrt {

namespace {

// ITU-T T.81, table B.1: the markers that carry no length field.
bool isStandalone(uint8_t marker) { return marker == 0x01 || (marker >= 0xD0 && marker <= 0xD9); }

// SOF0-SOF15 less DHT (C4), JPG (C8) and DAC (CC).
bool isFrameHeader(uint8_t marker)
{
    return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}

constexpr uint8_t kStartOfScan = 0xDA;
constexpr uint8_t kEndOfImage = 0xD9;

/// The offset just past a scan's entropy-coded data: the first FF that is
/// neither a stuffed zero (FF 00) nor a restart marker (FF D0-D7), or the
/// end of the bytes.
size_t endOfEntropyData(std::span<const uint8_t> bytes, size_t at)
{
    for (; at + 1 < bytes.size(); ++at) {
        if (bytes[at] != 0xFF) continue;
        const uint8_t next = bytes[at + 1];
        if (next == 0x00 || (next >= 0xD0 && next <= 0xD7) || next == 0xFF) continue;
        return at;
    }
    return bytes.size();
}

} // namespace

bool isJpeg(std::span<const uint8_t> bytes) { return bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8; }

std::optional<std::string> jpegStructureProblem(std::span<const uint8_t> bytes)
{
    if (!isJpeg(bytes)) return "it does not start with a JPEG start-of-image marker";
    bool frame = false, scan = false;
    size_t at = 2;
    while (true) {
        while (at < bytes.size() && bytes[at] == 0xFF && at + 1 < bytes.size() && bytes[at + 1] == 0xFF)
            ++at; // fill bytes
        if (at + 2 > bytes.size()) break;
        if (bytes[at] != 0xFF)
            return "byte " + std::to_string(at) + " should start a marker (FF), but is " + std::to_string(bytes[at]);
        const uint8_t marker = bytes[at + 1];
        at += 2;
        if (marker == kEndOfImage) {
            if (!frame) return "it ends (end-of-image marker) before any frame header";
            if (!scan) return "it ends (end-of-image marker) before any image data (no start-of-scan)";
            return std::nullopt;
        }
        if (isStandalone(marker)) continue;
        if (at + 2 > bytes.size()) break;
        const size_t length = size_t(bytes[at]) << 8 | bytes[at + 1];
        if (length < 2) return "the segment at byte " + std::to_string(at - 2) + " has a length below 2";
        if (at + length > bytes.size())
            return "the segment at byte " + std::to_string(at - 2) + " runs " + std::to_string(length) +
                   " bytes, past the file's end at " + std::to_string(bytes.size());
        frame |= isFrameHeader(marker);
        at += length;
        if (marker != kStartOfScan) continue;
        if (!frame) return "a scan (start-of-scan marker) comes before any frame header";
        const size_t end = endOfEntropyData(bytes, at);
        if (end == at) return "the scan at byte " + std::to_string(at - length - 2) + " holds no image data";
        if (end == bytes.size())
            return "it is truncated: the file ends inside its image data, before the end-of-image marker";
        scan = true;
        at = end;
    }
    if (!scan) return "it is truncated: the file ends before its image data (no start-of-scan marker)";
    return "it is truncated: the file ends before its end-of-image marker";
}

} // namespace vkrt
