#pragma once
// Changes made to a parsed scene from outside its file (command-line
// resolution, a regression case's size, the viewer's camera moves), checked
// with the scene parser's own limits and wording so that an override can never
// produce a Scene the parser would have refused.
#include "scene/Scene.h"

#include <optional>
#include <string>

namespace vkrt {

/// Image size from outside the scene file. `widthName`/`heightName` are how
/// errors name each value: "--width", or "suite.toml: case foo: width".
struct ResolutionOverride {
    std::optional<uint32_t> width, height;
    std::string widthName = "--width";
    std::string heightName = "--height";
};

/// Sets the camera's width and height; throws InputError "NAME: message" when
/// a side is outside [1, SceneLimits::maxImageSide] or width * height exceeds
/// SceneLimits::maxImagePixels (blaming the height when it was given, as the
/// parser does).
void applyResolution(Camera& camera, const ResolutionOverride& resolution);

/// The first reason the parser would refuse this camera ("fov: must be
/// strictly between 0 and 180 degrees, got 0"), or nullopt when it is valid.
/// Checks finite eye, target and up; eye != target; a non-zero up that is not
/// parallel to the view direction; fov in (0, 180); the image size.
std::optional<std::string> cameraProblem(const Camera& camera);

/// Throws InputError "what: problem" when cameraProblem finds one.
void checkCamera(const Camera& camera, const std::string& what);

} // namespace vkrt
