#pragma once
// What a finished render session writes: the mean, the variance layer and
// the AOV layers asked for, and the metadata, gathered once for every
// front end (`vkrt render`, the Python module) so that they write the same
// EXR from the same session.
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "render/RenderSession.h"

#include <map>
#include <string>
#include <vector>

namespace vkrt {

/// The AOVs a render may ask for, in the order their layers are written.
const std::vector<std::string>& aovNames();

/// `names` checked (each known, none twice); `what` names the option in
/// messages ("--aov", "aovs"). Throws InputError.
std::vector<std::string> checkedAovNames(const std::vector<std::string>& names, const std::string& what);

struct RenderOutput {
    Image mean;
    Metadata metadata;
    std::map<std::string, Image> layers;  ///< "variance" when asked for, "albedo"
    std::vector<ExrChannels> channels;    ///< N.X/Y/Z, P.X/Y/Z, Z
    std::vector<std::string> channelAovs; ///< the AOV of each of `channels`: "normal", "position", "depth"
};

/// The session's film as an EXR's contents: the variance layer when
/// `varianceLayer` and the kernel estimates it, the AOVs `aovs` names
/// (checkedAovNames) in compositors' conventions (Open Image Denoise reads
/// albedo.R/G/B and N.X/Y/Z; depth is Z, position P.X/Y/Z).
RenderOutput renderOutput(const RenderSession& session, Film film, bool varianceLayer,
                          const std::vector<std::string>& aovs);

/// Writes it as `vkrt render` does (atomically; io/ExrFile.h).
void writeRenderOutput(const std::filesystem::path& path, const RenderOutput& output);

/// The image formats a render's main output can have, chosen by its extension.
enum class ImageFormat {
    Exr, ///< .exr: OpenEXR, linear half/float, every layer and the metadata
    Png, ///< .png: the mean only, tone-mapped to 8-bit sRGB
};

/// The format `path`'s extension names (case-insensitive; /dev/null is
/// taken as EXR and discarded). Throws InputError "WHAT PATH: ..." listing the
/// formats for any other extension or none.
ImageFormat imageFormatOf(const std::filesystem::path& path, const std::string& what);

/// How a PNG output maps radiance to display values (--exposure, --filmic).
struct PngLook {
    float exposure = 0.0f;
    ToneCurve curve = ToneCurve::Clamp;
};

/// Writes the render to `path` in the format of its extension: the EXR of
/// writeRenderOutput, or a PNG of the mean. A PNG cannot hold layers, so an
/// output with a variance or AOV layer is refused there ("WHAT PATH: ...",
/// InputError) rather than written without them.
void writeRenderImage(const std::filesystem::path& path, const RenderOutput& output, const PngLook& look,
                      const std::string& what);

} // namespace vkrt
