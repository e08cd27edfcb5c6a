#include "io/ExrFile.h"

#include "io/AtomicFile.h"
#include "util/Error.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>

#include <algorithm>
#include <climits>
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

/// Points `frame` at `image` (already sized to the data window) for layer `layer`.
void addReadSlices(Imf::FrameBuffer& frame, const Imf::Header& header, const std::string& layer, Image& image,
                   const std::filesystem::path& path)
{
    const Imath::Box2i window = header.dataWindow();
    for (int c = 0; c < 3; ++c) {
        if (!header.channels().findChannel(channelName(layer, c)))
            throw InputError(path.string() + ": no channel '" + channelName(layer, c) + "'");
        char* base = reinterpret_cast<char*>(image.rgb.data() + c) -
                     (size_t(window.min.x) + size_t(window.min.y) * image.width) * sizeof(float) * 3;
        frame.insert(channelName(layer, c),
                     Imf::Slice(Imf::FLOAT, base, sizeof(float) * 3, sizeof(float) * 3 * image.width));
    }
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

} // namespace

void writeExr(const std::filesystem::path& path, const Image& image, const Metadata& metadata,
              const std::map<std::string, Image>& layers)
{
    useEveryCoreForExr();
    writeFileAtomically(path, [&](const std::filesystem::path& temporary) {
        Imf::Header header(int(image.width), int(image.height));
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const auto& [name, value] : metadata) addAttribute(header, name, value);
        Imf::FrameBuffer frame;
        addChannels(header, frame, "", image);
        for (const auto& [name, layer] : layers) addChannels(header, frame, name, layer);
        try {
            Imf::OutputFile file(temporary.c_str(), header);
            file.setFrameBuffer(frame);
            file.writePixels(int(image.height));
        } catch (const std::exception& e) {
            throw InputError(path.string() + ": cannot write EXR: " + e.what());
        }
    });
}

ExrContents readExr(const std::filesystem::path& path)
{
    if (!std::filesystem::exists(path)) throw InputError(path.string() + ": no such file");
    try {
        useEveryCoreForExr();
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const auto width = uint32_t(window.max.x - window.min.x + 1), height = uint32_t(window.max.y - window.min.y + 1);
        // Every layer in one pass: each compressed block holds all channels of its lines.
        ExrContents contents;
        Imf::FrameBuffer frame;
        contents.image = Image(width, height);
        addReadSlices(frame, file.header(), "", contents.image, path);
        std::set<std::string> layerNames;
        file.header().channels().layers(layerNames);
        for (const auto& name : layerNames) {
            Image& layer = contents.layers[name] = Image(width, height);
            addReadSlices(frame, file.header(), name, layer, path);
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        contents.metadata = readAttributes(file.header());
        return contents;
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(path.string() + ": not a readable EXR file: " + e.what());
    }
}

} // namespace vkrt
