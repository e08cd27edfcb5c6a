#include "view/CameraControl.h"

#include <algorithm>
#include <cmath>

namespace vkrt {

Camera orbit(const Camera& camera, double yawDegrees, double pitchDegrees)
{
    glm::dvec3 up = glm::normalize(camera.up);
    glm::dvec3 offset = camera.eye - camera.target;
    double distance = glm::length(offset);
    glm::dvec3 dir = offset / distance;
    // Decompose into the angle from `up` and an azimuth around it.
    double polar = std::acos(std::clamp(glm::dot(dir, up), -1.0, 1.0));
    glm::dvec3 horizontal = dir - glm::dot(dir, up) * up;
    glm::dvec3 side = glm::length(horizontal) > 1e-12 ? glm::normalize(horizontal) : glm::dvec3(0);
    if (side == glm::dvec3(0))
        side = std::abs(up.x) < 0.9 ? glm::normalize(glm::cross(up, glm::dvec3(1, 0, 0)))
                                    : glm::normalize(glm::cross(up, glm::dvec3(0, 0, 1)));
    glm::dvec3 tangent = glm::cross(up, side);
    double yaw = glm::radians(yawDegrees);
    glm::dvec3 rotatedSide = std::cos(yaw) * side + std::sin(yaw) * tangent;
    double limit = glm::radians(1.0);
    polar = std::clamp(polar - glm::radians(pitchDegrees), limit, M_PI - limit);
    Camera moved = camera;
    moved.eye = camera.target + distance * (std::cos(polar) * up + std::sin(polar) * rotatedSide);
    return moved;
}

Camera fly(const Camera& camera, double right, double up, double forward)
{
    glm::dvec3 view = camera.target - camera.eye;
    double distance = glm::length(view);
    glm::dvec3 f = view / distance;
    glm::dvec3 r = glm::normalize(glm::cross(f, camera.up));
    glm::dvec3 u = glm::cross(r, f);
    glm::dvec3 step = distance * (right * r + up * u + forward * f);
    Camera moved = camera;
    moved.eye += step;
    moved.target += step;
    return moved;
}

Camera zoom(const Camera& camera, double factor)
{
    Camera zoomed = camera;
    // A factor that is not > 0 has no field of view to clamp to: keep the
    // product (0, negative or NaN), which checkCamera/cameraProblem refuse.
    zoomed.fovY = factor > 0 ? std::clamp(camera.fovY * factor, 1.0, 170.0) : camera.fovY * factor;
    return zoomed;
}

} // namespace vkrt
