#pragma once
// Changes made to a parsed scene from outside its file (command-line
// resolution, a regression case's size, the viewer's camera moves), checked
// with the scene parser's own limits and wording so that an override can never
// produce a Scene the parser would have refused.
#include "scene/Scene.h"

#include <optional>
#include <string>

namespace vkrt {

// ------------------------------------------------- camera geometry rules
// Shared by the scene parser and the overrides below.

bool isFinite(const glm::dvec3& v);
/// Scaling by the largest component first lets legal extreme vectors (1e300 or
/// 1e-300) normalize without overflow or underflow; nullopt for the zero vector.
std::optional<glm::dvec3> normalized(const glm::dvec3& v);
/// to - from, halved when the full difference of two finite points overflows
/// (only its direction is used).
glm::dvec3 difference(const glm::dvec3& from, const glm::dvec3& to);
/// Whether two unit vectors are parallel to within 1e-6 (the sine of the
/// angle between them): an up vector that close to the view direction leaves
/// the camera's right vector numerically meaningless.
bool isParallel(const glm::dvec3& unitA, const glm::dvec3& unitB);

// ---------------------------------------------------------------- overrides

/// Image size from outside the scene file. `widthName`/`heightName` are how
/// errors name each value: "--width", or "suite.toml: case foo: width".
struct ResolutionOverride {
    std::optional<uint32_t> width, height;
    std::string widthName = "--width";
    std::string heightName = "--height";
};

/// Sets the camera's width and height; one of them alone keeps the camera's
/// aspect ratio (the other side scaled and rounded). Throws InputError "NAME: message" when
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
