#include "io/ExrFile.h"

#include "io/AtomicFile.h"
#include "io/ImageHeader.h"
#include "util/Error.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <memory>
#include <set>
#include <thread>

namespace vkrt {

namespace {

const char* const kChannels[3] = {"R", "G", "B"};

std::string channelName(const std::string& layer, int c)
{
    return layer.empty() ? kChannels[c] : layer + "." + kChannels[c];
}

void addChannels(Imf::Header& header, Imf::FrameBuffer& frame, const std::string& layer, const Image& image)
{
    for (int c = 0; c < 3; ++c) {
        header.channels().insert(channelName(layer, c), Imf::Channel(Imf::FLOAT));
        char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgb.data() + c));
        frame.insert(channelName(layer, c),
                     Imf::Slice(Imf::FLOAT, base, sizeof(float) * 3, sizeof(float) * 3 * image.width));
    }
}

void addAttribute(Imf::Header& header, const std::string& name, const MetadataValue& value)
{
    if (const auto* text = std::get_if<std::string>(&value)) {
        header.insert(name, Imf::StringAttribute(*text));
    } else if (const auto* integer = std::get_if<int64_t>(&value)) {
        if (*integer >= INT_MIN && *integer <= INT_MAX) header.insert(name, Imf::IntAttribute(int(*integer)));
        else header.insert(name, Imf::DoubleAttribute(double(*integer)));
    } else {
        header.insert(name, Imf::DoubleAttribute(std::get<double>(value)));
    }
}

Metadata readAttributes(const Imf::Header& header)
{
    Metadata metadata;
    for (auto it = header.begin(); it != header.end(); ++it) {
        const Imf::Attribute& attribute = it.attribute();
        if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&attribute)) metadata[it.name()] = s->value();
        else if (auto* i = dynamic_cast<const Imf::IntAttribute*>(&attribute))
            metadata[it.name()] = int64_t(i->value());
        else if (auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&attribute)) metadata[it.name()] = d->value();
    }
    return metadata;
}

/// Points `frame` at `image` for layer `layer`. The image has its size but no
/// pixels yet: its storage is reserved, so the slices stay valid as it grows.
void addReadSlices(Imf::FrameBuffer& frame, const Imf::Header& header, const std::string& layer, Image& image,
                   const std::filesystem::path& path)
{
    const Imath::Box2i window = header.dataWindow();
    image.rgb.reserve(image.pixelCount() * 3);
    for (int c = 0; c < 3; ++c) {
        if (!header.channels().findChannel(channelName(layer, c)))
            throw InputError(path.string() + ": no channel '" + channelName(layer, c) + "'");
        char* base =
            reinterpret_cast<char*>(image.rgb.data() + c) -
            (int64_t(window.min.x) + int64_t(window.min.y) * int64_t(image.width)) * int64_t(sizeof(float) * 3);
        frame.insert(channelName(layer, c),
                     Imf::Slice(Imf::FLOAT, base, sizeof(float) * 3, sizeof(float) * 3 * image.width));
    }
}

/// The channels that are neither the main R, G, B nor an RGB layer's, grouped
/// by their layer (the part before the last '.'), in the file's order.
std::map<std::string, ExrChannels> otherChannelsOf(const Imf::Header& header, const std::vector<std::string>& rgbLayers)
{
    std::set<std::string> taken{"R", "G", "B"};
    for (const std::string& layer : rgbLayers)
        for (int c = 0; c < 3; ++c) taken.insert(channelName(layer, c));
    std::map<std::string, ExrChannels> groups;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        const std::string name = it.name();
        if (taken.count(name)) continue;
        const size_t dot = name.rfind('.');
        groups[dot == std::string::npos ? name : name.substr(0, dot)].names.push_back(name);
    }
    return groups;
}

/// Slices for a group of channels, pixel-major as ExrChannels holds them; the
/// values are reserved, not touched (readPixelsInStrips grows them).
void addReadSlices(Imf::FrameBuffer& frame, const Imf::Header& header, ExrChannels& group, ImageExtent extent)
{
    const Imath::Box2i window = header.dataWindow();
    const size_t stride = group.names.size();
    group.values.reserve(size_t(extent.pixels()) * stride);
    for (size_t c = 0; c < stride; ++c) {
        char* base =
            reinterpret_cast<char*>(group.values.data() + c) -
            (int64_t(window.min.x) + int64_t(window.min.y) * int64_t(extent.width)) * int64_t(sizeof(float) * stride);
        frame.insert(group.names[c],
                     Imf::Slice(Imf::FLOAT, base, sizeof(float) * stride, sizeof(float) * stride * extent.width));
    }
}

/// Rows per readPixels call: a multiple of every compression's block height (1, 16, 32, 256).
constexpr int kStripRows = 256;

/// Reads the rows strip by strip, each image growing (and its memory being
/// touched) only by the rows just read: a header that claims more pixels
/// than the file holds fails at the first missing block, not after
/// allocating them all.
void readPixelsInStrips(Imf::InputFile& file, const std::vector<Image*>& images,
                        const std::vector<ExrChannels*>& groups = {})
{
    const Imath::Box2i window = file.header().dataWindow();
    const int height = window.max.y - window.min.y + 1;
    const size_t width = size_t(window.max.x - window.min.x + 1);
    for (int row = 0; row < height; row += kStripRows) {
        const int rows = std::min(kStripRows, height - row);
        for (Image* image : images) image->rgb.resize(size_t(row + rows) * image->width * 3);
        for (ExrChannels* group : groups) group->values.resize(size_t(row + rows) * width * group->names.size());
        file.readPixels(window.min.y + row, window.min.y + row + rows - 1);
    }
}

/// An image of the data window's size whose pixels are still to be read.
Image unreadImage(ImageExtent extent)
{
    Image image;
    image.width = extent.width;
    image.height = extent.height;
    return image;
}

void checkExpectedSize(const std::filesystem::path& path, ImageExtent found,
                       const std::optional<ExpectedSize>& expected)
{
    if (expected && (found.width != expected->width || found.height != expected->height))
        throw InputError(path.string() + ": " + found.str() + " pixels, but " + expected->source + " " +
                         ImageExtent{expected->width, expected->height}.str());
}

/// The file opened and its header checked (ImageHeader.h) before OpenEXR allocates anything from it.
class CheckedExrInput {
public:
    CheckedExrInput(const std::filesystem::path& path, const std::optional<ExpectedSize>& expected)
        : m_stream(openStream(path)),
          m_header(readCheckedExrHeader(*m_stream, std::filesystem::file_size(path), path.string()))
    {
        checkExpectedSize(path, extentOf(m_header), expected);
    }

    const Imf::Header& header() const { return m_header; }
    /// OpenEXR's reader on the same stream, from its start.
    Imf::InputFile open()
    {
        m_stream->seekg(0);
        return Imf::InputFile(*m_stream, Imf::globalThreadCount());
    }

private:
    static std::unique_ptr<Imf::StdIFStream> openStream(const std::filesystem::path& path)
    {
        if (!std::filesystem::exists(path)) throw InputError(path.string() + ": no such file");
        if (!std::filesystem::is_regular_file(path)) throw InputError(path.string() + ": is not a regular file");
        return std::make_unique<Imf::StdIFStream>(path.c_str());
    }

    std::unique_ptr<Imf::StdIFStream> m_stream;
    Imf::Header m_header;
};

/// The layers with R, G and B channels (others, such as an AOV's "N.X",
/// "N.Y", "N.Z", are not vkrt's to read).
std::vector<std::string> layerNamesOf(const Imf::Header& header)
{
    std::set<std::string> names;
    header.channels().layers(names);
    std::vector<std::string> rgb;
    for (const std::string& name : names)
        if (header.channels().findChannel(name + ".R") && header.channels().findChannel(name + ".G") &&
            header.channels().findChannel(name + ".B"))
            rgb.push_back(name);
    return rgb;
}

/// OpenEXR (de)compresses blocks of lines on its own thread pool, which is
/// empty unless set: with it, a 4K shard with five layers reads and writes
/// several times faster on a many-core node.
void useEveryCoreForExr()
{
    static const bool done = [] {
        Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
        return true;
    }();
    (void)done;
}

/// An OpenEXR output stream into memory. OpenEXR writes its line offset
/// table last, seeking back over the placeholder it wrote after the header,
/// so writes may overwrite earlier bytes as well as append.
class MemoryOStream : public Imf::OStream {
public:
    explicit MemoryOStream(size_t expectedBytes) : Imf::OStream("memory")
    {
        // Reserved, not touched: only the bytes written become resident, and
        // the buffer is never copied to grow (which would double the peak).
        m_bytes.reserve(expectedBytes);
    }

    void write(const char c[], int n) override
    {
        const size_t end = m_position + size_t(n);
        if (end > m_bytes.size()) m_bytes.resize(end);
        std::memcpy(m_bytes.data() + m_position, c, size_t(n));
        m_position = end;
    }
    uint64_t tellp() override { return m_position; }
    void seekp(uint64_t position) override { m_position = size_t(position); }

    std::string take() { return std::move(m_bytes); }

private:
    std::string m_bytes;
    size_t m_position = 0;
};

/// An upper bound of the encoded size: ZIP blocks that would not shrink are
/// stored raw, so the pixels never take more than their own bytes; the rest
/// (header, offset table, block headers) is small beside them.
size_t encodedSizeBound(const Image& image, const Metadata& metadata, size_t layerCount)
{
    constexpr size_t kZipBlockRows = 16, kHeaderAllowance = 64 * 1024;
    size_t bound = image.pixelCount() * 3 * sizeof(float) * (1 + layerCount);
    bound += (image.height / kZipBlockRows + 1) * 16 + kHeaderAllowance;
    for (const auto& [name, value] : metadata)
        if (const auto* text = std::get_if<std::string>(&value)) bound += name.size() + text->size() + 32;
    return bound;
}

/// The whole EXR file in memory. OpenEXR writes to a std::ofstream without
/// checking its last buffered flush (a full disk gave an empty file and
/// success), so vkrt encodes first and writes with writeBytesAtomically,
/// which checks every write. Costs the encoded file's size in memory once.
void addChannels(Imf::Header& header, Imf::FrameBuffer& frame, const ExrChannels& channels, uint32_t width)
{
    const size_t stride = channels.names.size();
    for (size_t c = 0; c < stride; ++c) {
        header.channels().insert(channels.names[c], Imf::Channel(Imf::FLOAT));
        char* base = reinterpret_cast<char*>(const_cast<float*>(channels.values.data() + c));
        frame.insert(channels.names[c],
                     Imf::Slice(Imf::FLOAT, base, sizeof(float) * stride, sizeof(float) * stride * width));
    }
}

std::string encodeExr(const Image& image, const Metadata& metadata, const std::map<std::string, Image>& layers,
                      const std::vector<ExrChannels>& channels)
{
    Imf::Header header(int(image.width), int(image.height));
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& [name, value] : metadata) addAttribute(header, name, value);
    Imf::FrameBuffer frame;
    addChannels(header, frame, "", image);
    for (const auto& [name, layer] : layers) addChannels(header, frame, name, layer);
    size_t extraLayers = layers.size();
    for (const ExrChannels& set : channels) {
        VKRT_CHECK(set.values.size() == set.names.size() * image.pixelCount());
        addChannels(header, frame, set, image.width);
        extraLayers += 1; // at most three channels each
    }
    MemoryOStream stream(encodedSizeBound(image, metadata, extraLayers));
    {
        // The offset table is written when the file is destroyed: the bytes are whole only after this block.
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(int(image.height));
    }
    return stream.take();
}

} // namespace

void writeExr(const std::filesystem::path& path, const Image& image, const Metadata& metadata,
              const std::map<std::string, Image>& layers, const std::vector<ExrChannels>& channels)
{
    if (resolveOutputTarget(path).kind == OutputTargetKind::Discarded) return; // before the encode's cost
    useEveryCoreForExr();
    std::string encoded;
    try {
        encoded = encodeExr(image, metadata, layers, channels);
    } catch (const std::exception& e) {
        throw InputError(path.string() + ": cannot write EXR: " + e.what());
    }
    writeBytesAtomically(path, encoded);
}

ExrHeader readExrHeader(const std::filesystem::path& path, const std::optional<ExpectedSize>& expected)
{
    try {
        CheckedExrInput input(path, expected);
        const ImageExtent extent = extentOf(input.header());
        return {extent.width, extent.height, layerNamesOf(input.header()), readAttributes(input.header())};
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path.string() + ": not a readable EXR file: " + e.what());
    }
}

ExrContents readExr(const std::filesystem::path& path, const std::optional<ExpectedSize>& expected)
{
    try {
        useEveryCoreForExr();
        CheckedExrInput input(path, expected);
        Imf::InputFile file = input.open();
        const ImageExtent extent = extentOf(file.header());
        // Every layer in one pass: each compressed block holds all channels of its lines.
        ExrContents contents;
        Imf::FrameBuffer frame;
        contents.image = unreadImage(extent);
        addReadSlices(frame, file.header(), "", contents.image, path);
        std::vector<Image*> images{&contents.image};
        const std::vector<std::string> rgbLayers = layerNamesOf(file.header());
        for (const auto& name : rgbLayers) {
            Image& layer = contents.layers[name] = unreadImage(extent);
            addReadSlices(frame, file.header(), name, layer, path);
            images.push_back(&layer);
        }
        contents.channels = otherChannelsOf(file.header(), rgbLayers);
        std::vector<ExrChannels*> groups;
        for (auto& [name, group] : contents.channels) {
            addReadSlices(frame, file.header(), group, extent);
            groups.push_back(&group);
        }
        file.setFrameBuffer(frame);
        readPixelsInStrips(file, images, groups);
        contents.metadata = readAttributes(file.header());
        return contents;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path.string() + ": not a readable EXR file: " + e.what());
    }
}

} // namespace vkrt
