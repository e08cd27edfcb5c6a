#include "render/RenderOutput.h"

#include "io/AtomicFile.h"
#include "scene/TomlReader.h"
#include "util/Error.h"

#include <algorithm>
#include <cctype>

namespace vkrt {

const std::vector<std::string>& aovNames()
{
    static const std::vector<std::string> names{"albedo", "normal", "depth", "position"};
    return names;
}

std::vector<std::string> checkedAovNames(const std::vector<std::string>& names, const std::string& what)
{
    const std::vector<std::string>& known = aovNames();
    std::vector<std::string> checked;
    for (const std::string& name : names) {
        if (std::find(known.begin(), known.end(), name) == known.end()) {
            const std::vector<std::string_view> options(known.begin(), known.end());
            throw InputError(what + ": unknown AOV " + quote(name) + didYouMean(name, options) + " (" +
                             joinList(options) + ")");
        }
        if (std::find(checked.begin(), checked.end(), name) != checked.end())
            throw InputError(what + ": " + quote(name) + " is named twice");
        checked.push_back(name);
    }
    return checked;
}

namespace {

std::string joined(const std::vector<std::string>& names)
{
    std::string text;
    for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
    return text;
}

} // namespace

RenderOutput renderOutput(const RenderSession& session, Film film, bool varianceLayer,
                          const std::vector<std::string>& aovs)
{
    RenderOutput out;
    out.metadata = session.metadata(film);
    if (film.variance && varianceLayer) out.layers["variance"] = std::move(*film.variance);
    out.mean = std::move(film.mean);
    if (aovs.empty()) return out;
    const AovImages images = session.renderer().aovs();
    for (const std::string& name : aovs) {
        if (name == "albedo") {
            out.layers["albedo"] = images.albedo;
            continue;
        }
        if (name == "normal") out.channels.push_back({{"N.X", "N.Y", "N.Z"}, images.normal.rgb});
        if (name == "position") out.channels.push_back({{"P.X", "P.Y", "P.Z"}, images.position.rgb});
        if (name == "depth") out.channels.push_back({{"Z"}, images.depth});
        out.channelAovs.push_back(name);
    }
    out.metadata["aovs"] = joined(aovs);
    return out;
}

void writeRenderOutput(const std::filesystem::path& path, const RenderOutput& output)
{
    writeExr(path, output.mean, output.metadata, output.layers, output.channels);
}

ImageFormat imageFormatOf(const std::filesystem::path& path, const std::string& what)
{
    std::string extension = path.extension().string();
    for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".exr") return ImageFormat::Exr;
    if (extension == ".png") return ImageFormat::Png;
    if (resolveOutputTarget(path).kind == OutputTargetKind::Discarded) return ImageFormat::Exr;
    throw InputError(
        what + " " + path.string() + ": " +
        (extension.empty() ? std::string("has no extension") : "unknown image format '" + extension + "'") +
        "; vkrt writes .exr (OpenEXR: linear HDR, every layer) or .png (8-bit sRGB, tone-mapped)");
}

void writeRenderImage(const std::filesystem::path& path, const RenderOutput& output, const PngLook& look,
                      const std::string& what)
{
    if (imageFormatOf(path, what) == ImageFormat::Exr) return writeRenderOutput(path, output);
    if (!output.layers.empty() || !output.channels.empty()) {
        std::string layers;
        for (const auto& [name, layer] : output.layers) layers += (layers.empty() ? "" : ", ") + name;
        for (const std::string& aov : output.channelAovs) layers += (layers.empty() ? "" : ", ") + aov;
        throw InputError(what + " " + path.string() + ": a PNG holds only the image, not its " + layers +
                         " layers; write an .exr (with --png for a preview)");
    }
    writePng(path, output.mean, look.exposure, look.curve);
}

} // namespace vkrt
