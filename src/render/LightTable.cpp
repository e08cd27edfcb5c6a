#include "render/LightTable.h"

#include "scene/kinds/Kinds.h"
#include "util/Error.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace vkrt {

namespace {

double meanOf(const glm::vec3& c) { return (double(c.r) + double(c.g) + double(c.b)) / 3.0; }

/// One light's power (what the table is proportional to). A kind in the
/// registry without its overload fails to build.
double lightPower(const gpu::PointLight& light, double) { return 4.0 * glm::pi<double>() * meanOf(light.intensity); }

double lightPower(const gpu::SpotLight& light, double)
{
    // The falloff t^2, t = clamp((cos a - cosOuter) falloffScale, 0, 1),
    // integrated over the sphere: 2 pi ((1 - cosInner) + (cosInner - cosOuter) / 3),
    // cosInner = cosOuter + 1 / falloffScale; a hard edge is the cap 1 - cosOuter.
    const double cosOuter = light.cosOuter;
    double solidAngle = 1.0 - cosOuter;
    if (light.falloffScale > 0.0f) {
        const double cosInner = std::min(1.0, cosOuter + 1.0 / double(light.falloffScale));
        solidAngle = (1.0 - cosInner) + (cosInner - cosOuter) / 3.0;
    }
    return 2.0 * glm::pi<double>() * std::max(0.0, solidAngle) * meanOf(light.intensity);
}

double lightPower(const gpu::DirectionalLight& light, double sceneRadius)
{
    // A delta sun's radiance is its irradiance; a cone's is E / (pi sin^2 alpha).
    const double irradiance = light.oneMinusCos > 0.0f
                                  ? meanOf(light.radiance) * glm::pi<double>() * double(light.sin2Alpha)
                                  : meanOf(light.radiance);
    return irradiance * glm::pi<double>() * sceneRadius * sceneRadius;
}

/// One kind's entries: one per record, or none for triangle lights (emitters).
template <class GpuRecord>
void appendPowers(const std::vector<GpuRecord>& records, double sceneRadius, std::vector<double>& powers)
{
    if constexpr (!std::is_same_v<GpuRecord, gpu::TriangleLight>) {
        for (const GpuRecord& record : records) {
            const double power = lightPower(record, sceneRadius);
            // A light whose power does not fit a double's range is never drawn (power 0).
            powers.push_back(std::isfinite(power) && power > 0.0 ? power : 0.0);
        }
    }
}

template <bool Bounded, class Record>
void extendByRecords(const std::vector<Record>& records, Aabb& box)
{
    if constexpr (Bounded) {
        for (const Record& record : records) {
            const Aabb bounds = boundsOf(record);
            if (!bounds.empty()) box.extend(bounds);
        }
    }
}

} // namespace

std::vector<double> lightTablePowers(const GpuSceneData& data, double emitterPower, double sceneRadius)
{
    std::vector<double> powers;
#define VKRT_APPEND_POWERS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    appendPowers(data.array, sceneRadius, powers);
    VKRT_LIGHT_KINDS(VKRT_APPEND_POWERS)
#undef VKRT_APPEND_POWERS
    if (!data.emitters.empty()) powers.push_back(std::isfinite(emitterPower) ? emitterPower : 0.0);
    return powers;
}

double sceneBoundingRadius(const Scene& scene)
{
    Aabb box;
    box.extend(scene.camera.eye);
#define VKRT_EXTEND_BY_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    extendByRecords<bounded != 0>(scene.array, box);
    VKRT_SHAPE_KINDS(VKRT_EXTEND_BY_KIND)
    VKRT_LIGHT_KINDS(VKRT_EXTEND_BY_KIND)
#undef VKRT_EXTEND_BY_KIND
    for (const PointLight& light : scene.pointLights) box.extend(light.position);
    for (const SpotLight& light : scene.spotLights) box.extend(light.position);
    const double radius = 0.5 * glm::length(box.upper - box.lower);
    // A scene of one point has no extent: any radius gives the suns the same share.
    return std::isfinite(radius) && radius > 0.0 ? radius : 1.0;
}

void buildLightTable(const Scene& scene, const GpuSceneStatic& fixed, GpuSceneData& data)
{
    const EmitterTable table =
        aliasTable(lightTablePowers(data, fixed.emitters.totalPower, sceneBoundingRadius(scene)));
    data.lightTable.clear();
    for (size_t i = 0; i < table.pdf.size(); ++i)
        data.lightTable.push_back(gpu::LightPick{float(table.pdf[i]), table.threshold[i], table.alias[i]});
    VKRT_CHECK(!data.lightTable.empty());
    data.uniforms.lightTableCount = uint32_t(data.lightTable.size());
    data.uniforms.lightCandidates = kLightTableCandidates;
    if (data.emitters.empty()) return;
    // The emitters' entry is the last: each emitter's density becomes that of
    // drawing it among the candidates (lib/lights.glsl: emitterOnHit's MIS too).
    const double emittersEntry = double(kLightTableCandidates) * table.pdf.back();
    for (gpu::Emitter& e : data.emitters) e.pdf = float(double(e.pdf) * emittersEntry);
}

} // namespace vkrt
