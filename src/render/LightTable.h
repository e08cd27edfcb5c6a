#pragma once
// The light table of scenes with many lights (shared/SceneTypes.h: LightPick;
// the kernel's side is lib/lights.glsl, VKRT_LIGHT_TABLE). A scene with at
// most kMaxEnumeratedLights (scene/FeatureSet.h) point, spot and directional lights keeps the
// kernel that tests every light at every shading point (no added noise);
// beyond that its cost would grow with the lights, so each shading point
// draws kLightTableCandidates lights from a table chosen in proportion to
// power instead, and traces one shadow ray.
#include "render/GpuScene.h"
#include "scene/FeatureSet.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vkrt {

/// Lights drawn from the table per shading point (resampled to one shadow
/// ray): 8 measured the most efficient of 1, 4, 8 and 16 (docs/performance.md,
/// "Many lights").
inline constexpr uint32_t kLightTableCandidates = 8;

/// Each table entry's power: a point light 4 pi I, a spot light I times the
/// solid angle of its falloff (exact for KHR_lights_punctual's), a sun its
/// irradiance on a disc of the scene's bounding radius (pbrt's estimate), and
/// the emitters together their total power (`emitterPower`). Radiometric
/// quantities are the mean of their three channels, as the emitters'.
std::vector<double> lightTablePowers(const GpuSceneData& data, double emitterPower, double sceneRadius);

/// The radius of a sphere around everything the scene bounds (shapes with
/// bounds, lights with a position, the eye): the disc a sun's power falls on.
double sceneBoundingRadius(const Scene& scene);

/// Fills data.lightTable and the uniforms' table size and candidates, and
/// scales every emitter's pdf to the density of drawing it among the
/// candidates (kLightTableCandidates times its entry's probability times its
/// own). Directional lights must already be in their upload order.
void buildLightTable(const Scene& scene, const GpuSceneStatic& fixed, GpuSceneData& data);

} // namespace vkrt
