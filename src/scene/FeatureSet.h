#pragma once
// What a scene uses, reduced to the flags that select a kernel variant.
// Data flow: Scene -> FeatureSet -> defines -> SPIR-V (cached) -> pipeline.
// A new feature adds a flag here, a define in defines() and guarded GLSL.
#include "scene/Scene.h"

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace vkrt {

struct FeatureSet {
    bool spheres = false;
    bool boxes = false;
    bool triangles = false;
    bool planes = false;
    bool pointLights = false;
    bool triangleLights = false;
    bool cubemap = false;
    bool environmentSampling = false; ///< importance-sample the cubemap (path integrator)
    bool variance = false; ///< per-pixel variance estimation (not a scene property: a render option)
    bool sobolSampler = false; ///< Owen-scrambled Sobol' points instead of independent ones (a render option)
    bool uniformScene = false; ///< scene arrays in uniform buffers: every array fits (shared/SceneTypes.h)
    std::array<bool, 5> materialTypes{}; ///< indexed by MaterialType
    Integrator integrator = Integrator::Whitted;

    /// Every feature on: the "uber" kernel, for comparison (`--uber`).
    static FeatureSet everything(Integrator integrator);

    bool anyPrimitive() const { return spheres || boxes || triangles || planes; }
    bool has(MaterialType type) const { return materialTypes[size_t(type)]; }

    /// Preprocessor defines selecting this variant, in a stable order.
    std::vector<std::pair<std::string, std::string>> defines() const;
    /// Descriptor binding indices (shaders/shared/Bindings.h) this variant declares.
    std::vector<uint32_t> bindings() const;
    /// Whether this variant declares `binding` as a uniform buffer.
    bool isUniformBinding(uint32_t binding) const;
    /// One line for people, e.g. "whitted; spheres planes; lambert; point-lights".
    std::string describe() const;

    bool operator==(const FeatureSet&) const = default;
};

FeatureSet featuresOf(const Scene& scene);

/// Whether every scene array of the scene fits the uniform-buffer capacities.
bool sceneFitsUniformBuffers(const Scene& scene);

std::string integratorName(Integrator integrator);
std::string materialTypeName(MaterialType type);

} // namespace vkrt
