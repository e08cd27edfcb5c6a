#include "scene/SceneOverrides.h"

#include "scene/TomlReader.h"
#include "util/KernelLimits.h"

#include <algorithm>
#include <cmath>

namespace vkrt {

namespace {

std::optional<std::string> sideProblem(uint32_t side)
{
    if (side >= 1 && side <= SceneLimits::maxImageSide) return std::nullopt;
    // Appended, not `std::string&& + "..."`: GCC 14 reports a false -Warray-bounds there at -O2.
    std::string problem = "must be between 1 and " + std::to_string(SceneLimits::maxImageSide);
    problem.append(", got ").append(std::to_string(side));
    return problem;
}

std::optional<std::string> pixelCountProblem(uint32_t width, uint32_t height)
{
    uint64_t pixels = uint64_t{width} * height;
    if (pixels <= SceneLimits::maxImagePixels) return std::nullopt;
    return "width * height = " + std::to_string(pixels) + " pixels exceeds the limit of " +
           std::to_string(SceneLimits::maxImagePixels);
}

std::optional<std::string> upProblem(const Camera& camera)
{
    std::optional<glm::dvec3> up = normalized(camera.up);
    if (!up) return "up: must not be zero-length";
    glm::dvec3 view = *normalized(difference(camera.eye, camera.target));
    if (!isParallel(*up, view)) return std::nullopt;
    return "up: must not be parallel to the view direction (target - eye)";
}

std::optional<std::string> lensProblem(const Camera& camera)
{
    const std::string range = " (the kernel's float32 holds lengths up to " + formatNumber(kMaxKernelMagnitude) + ")";
    if (!(camera.apertureRadius >= 0 && camera.apertureRadius <= kMaxKernelMagnitude))
        return "aperture_radius: must be between 0 and " + formatNumber(kMaxKernelMagnitude) + ", got " +
               formatNumber(camera.apertureRadius) + range;
    if (camera.focusDistance && !(*camera.focusDistance > 0 && *camera.focusDistance <= kMaxKernelMagnitude))
        return "focus_distance: must be positive and at most " + formatNumber(kMaxKernelMagnitude) + ", got " +
               formatNumber(*camera.focusDistance) + range;
    // The default, the distance to the target, can be as far for far-apart points.
    if (camera.thinLens() && !(camera.resolvedFocusDistance() <= kMaxKernelMagnitude))
        return "focus_distance: the distance from eye to target, " + formatNumber(camera.resolvedFocusDistance()) +
               ", is too far to focus at" + range + "; set focus_distance";
    if (!(camera.orthographicHeight >= 0 && camera.orthographicHeight <= kMaxKernelMagnitude))
        return "orthographic height: must be between 0 and " + formatNumber(kMaxKernelMagnitude) + ", got " +
               formatNumber(camera.orthographicHeight) + range;
    if (camera.orthographic() && camera.thinLens())
        return std::string("aperture_radius: an orthographic camera has no lens");
    return std::nullopt;
}

} // namespace

bool isFinite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::optional<glm::dvec3> normalized(const glm::dvec3& v)
{
    double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (largest == 0) return std::nullopt;
    return glm::normalize(v / largest);
}

glm::dvec3 difference(const glm::dvec3& from, const glm::dvec3& to)
{
    glm::dvec3 d = to - from;
    return isFinite(d) ? d : to * 0.5 - from * 0.5;
}

bool isParallel(const glm::dvec3& unitA, const glm::dvec3& unitB)
{
    return glm::length(glm::cross(unitA, unitB)) < 1e-6;
}

void applyResolution(Camera& camera, const ResolutionOverride& resolution)
{
    auto side = [](const std::optional<uint32_t>& value, const std::string& name, uint32_t current) {
        if (!value) return current;
        if (auto problem = sideProblem(*value)) throw InputError(name + ": " + *problem);
        return *value;
    };
    uint32_t width = side(resolution.width, resolution.widthName, camera.width);
    uint32_t height = side(resolution.height, resolution.heightName, camera.height);
    // One side alone keeps the scene's aspect ratio (--width 160 on a 640 x 480
    // scene is 160 x 120, not a 160 x 480 sliver), rounded, at least 1 pixel.
    auto scaled = [](uint32_t given, uint32_t from, uint32_t to) {
        return uint32_t(std::max(1.0, std::round(double(given) * double(to) / double(from))));
    };
    const std::string aspect = std::to_string(camera.width) + "x" + std::to_string(camera.height);
    if (resolution.width && !resolution.height) {
        height = scaled(width, camera.width, camera.height);
        if (auto problem = sideProblem(height))
            throw InputError(resolution.widthName + ": the height that keeps the scene's aspect ratio (" + aspect +
                             ") " + *problem + "; give " + resolution.heightName + " too");
    } else if (resolution.height && !resolution.width) {
        width = scaled(height, camera.height, camera.width);
        if (auto problem = sideProblem(width))
            throw InputError(resolution.heightName + ": the width that keeps the scene's aspect ratio (" + aspect +
                             ") " + *problem + "; give " + resolution.widthName + " too");
    }
    if (auto problem = pixelCountProblem(width, height))
        throw InputError((resolution.height ? resolution.heightName : resolution.widthName) + ": " + *problem);
    camera.width = width;
    camera.height = height;
}

std::optional<std::string> cameraProblem(const Camera& camera)
{
    if (!isFinite(camera.eye)) return std::string("eye: must be finite");
    if (!isFinite(camera.target)) return std::string("target: must be finite");
    if (!isFinite(camera.up)) return std::string("up: must be finite");
    if (camera.target == camera.eye)
        return std::string("target: must differ from camera.eye (the view direction would be undefined)");
    if (auto problem = upProblem(camera)) return problem;
    if (!(camera.fovY > 0 && camera.fovY < 180))
        return "fov: must be strictly between 0 and 180 degrees, got " + formatNumber(camera.fovY);
    if (auto problem = lensProblem(camera)) return problem;
    if (auto problem = sideProblem(camera.width)) return "width: " + *problem;
    if (auto problem = sideProblem(camera.height)) return "height: " + *problem;
    if (auto problem = pixelCountProblem(camera.width, camera.height)) return "height: " + *problem;
    return std::nullopt;
}

void checkCamera(const Camera& camera, const std::string& what)
{
    if (auto problem = cameraProblem(camera)) throw InputError(what + ": " + *problem);
}

} // namespace vkrt
