#pragma once
// Value readers the scene format uses in more than one place (the parser and
// the kinds' readers in scene/kinds/): colours, vertices, indices of
// refraction, files that must exist.
#include "scene/Scene.h"
#include "scene/TomlReader.h"

#include <array>
#include <filesystem>

namespace vkrt {

/// An index of refraction in [1, SceneLimits::maxIor].
double readIor(const Field& field);

/// Three points (a triangle's vertices).
std::array<glm::dvec3, 3> readVertices(const Field& field);

enum class ColorRange { Unit, NonNegative };

/// A colour is three channels or one number meaning grey; every channel
/// finite in 32-bit floats (the GPU's), and in [0, 1] for ColorRange::Unit.
Color readColor(const Field& field, ColorRange range);
Color readUnitColor(const Field& field);
Color readRadiance(const Field& field);

/// `rotate = { axis = [x, y, z], angle = degrees }`, right-handed about the
/// axis (meshes, the environment map).
glm::dmat4 readRotation(const Field& field);

/// Fails at `field` unless `path` names an existing regular file.
void checkRegularFile(const Field& field, const std::filesystem::path& path);

} // namespace vkrt
