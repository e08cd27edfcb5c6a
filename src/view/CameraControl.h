#pragma once
// Camera moves of the viewer, on the scene's Camera: orbit around the
// target, fly (move eye and target together), zoom (field of view).
#include "scene/Scene.h"

namespace vkrt {

/// Turns the eye around the target by yaw (about `up`) and pitch (towards
/// `up`) in degrees, keeping its distance; pitch stops 1 degree short of the
/// poles so that `up` never becomes parallel to the view direction.
Camera orbit(const Camera& camera, double yawDegrees, double pitchDegrees);

/// Moves eye and target along the camera's right, up and forward axes, in
/// units of the eye-target distance.
Camera fly(const Camera& camera, double right, double up, double forward);

/// Multiplies the vertical field of view by `factor` > 0, kept inside [1, 170]
/// degrees. Any other factor collapses the view: the result is an invalid
/// camera (fov <= 0 or NaN) that the viewer refuses (SceneOverrides.h).
Camera zoom(const Camera& camera, double factor);

} // namespace vkrt
