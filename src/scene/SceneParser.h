#pragma once
// Reading scene files (TOML, documented in docs/scene-format.md) into a
// validated Scene. All checking happens here so that the rest of vkrt can trust
// every value it gets.
#include "scene/Scene.h"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace vkrt {

/// Reads, parses and validates a scene file; throws SceneError (with file:line:column) or InputError (unreadable file).
Scene parseSceneFile(const std::string& path);

/// A warning when a lat-long environment map is not 2:1 (width 2 h or
/// 2 (h - 1)): a cubemap face or a photo read as a sky stretches it. Nothing
/// when it is, or when its header cannot be read (the render names that error).
std::optional<std::string> latLongShapeWarning(const EnvironmentMap& map, const std::string& what);

/// Same for text in memory; `path` is used in messages and to resolve relative paths (cubemap faces) against its
/// directory.
Scene parseSceneString(std::string_view text, const std::string& path = "<string>");

/// One material table (the keys of `[materials.NAME]`, `type` included) as
/// the scene parser reads it, for a material changed from outside its file
/// (the Python module). `source` names the text in errors; textures are
/// refused. Throws SceneError.
Material parseMaterialTable(std::string_view text, const std::string& source, const std::string& name,
                            const std::filesystem::path& baseDir = {});

} // namespace vkrt
