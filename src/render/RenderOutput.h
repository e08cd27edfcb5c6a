#pragma once
// What a finished render session writes: the mean, the variance layer and
// the AOV layers asked for, and the metadata, gathered once for every
// front end (`vkrt render`, the Python module) so that they write the same
// EXR from the same session.
#include "io/ExrFile.h"
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

} // namespace vkrt
