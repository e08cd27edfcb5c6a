#pragma once
// The validated Scene as JSON (docs/scene-json.md): what vkrt parsed, every
// default filled in and every path absolute, so that tools (to_mitsuba.py)
// read the scene vkrt renders instead of parsing the TOML again.
#include "scene/Scene.h"

#include <nlohmann/json_fwd.hpp>

#include <string>

namespace vkrt {

/// The schema's version (docs/scene-json.md); raised when a field changes meaning or goes away.
inline constexpr int kSceneJsonVersion = 1;

/// The whole scene as a JSON object: camera, render settings, materials, one
/// array per shape and light kind of the registry (shared/Kinds.h), background,
/// textures and warnings.
nlohmann::ordered_json exportScene(const Scene& scene);

/// exportScene as text, indented, ending in a newline; doubles round-trip exactly.
std::string exportSceneText(const Scene& scene);

} // namespace vkrt
