#pragma once
// Material parameters given as textures in scene files:
//   albedo = { texture = "wood.png", scale = [4, 4], linear = false, wrap = "repeat", filter = "linear",
//              channel = "r" }
//   normal_map = { texture = "bumps.png", scale = [2, 2], wrap = "clamp", strength = 1 }
// (docs/scene-format.md, "Textures"). The image is loaded here, at parse time,
// into the scene's TextureAtlas, so a missing or unreadable file is reported
// at the `texture` key like every other scene error.
#include "scene/Scene.h"
#include "scene/TomlReader.h"
#include "texture/TextureAtlas.h"

namespace vkrt {

/// What a texture table may hold for a colour or scalar parameter.
/// Color: sRGB unless `linear`; Scalar: one `channel`; NormalMap: linear, with
/// `strength`; Vector: linear, read whole (pbr anisotropy directions).
enum class TextureUse { Color, Scalar, NormalMap, Vector };

/// Whether `field` is a texture table (rather than a value).
bool isTextureTable(const Field& field);

/// Reads a texture table: loads the image into `atlas` and returns the slot.
/// `use` decides the keys allowed: `channel` for scalars, `strength` for normal
/// maps (always linear); `strength` is returned through `normalStrength`.
MaterialTexture readTextureTable(const Field& field, TextureUse use, TextureAtlas& atlas,
                                 double* normalStrength = nullptr);

} // namespace vkrt
