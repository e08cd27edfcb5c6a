#pragma once
// Scene -> the GPU records of shaders/shared/SceneTypes.h. Positions are made
// camera-relative in double precision before rounding to float32, so a scene
// far from the world origin keeps full float precision near the camera.
#include "scene/Scene.h"
#include "shared/SceneTypes.h"

#include <vector>

namespace vkrt {

struct GpuSceneData {
    gpu::SceneUniforms uniforms{};
    std::vector<gpu::Material> materials;
    // One array per shape and light kind (shared/Kinds.h), named as in Scene.
#define VKRT_GPU_ARRAY_MEMBER(KIND, Type, name, value, field, array, ARRAY, capacity) std::vector<gpu::Type> array;
    VKRT_SHAPE_KINDS(VKRT_GPU_ARRAY_MEMBER)
    VKRT_LIGHT_KINDS(VKRT_GPU_ARRAY_MEMBER)
#undef VKRT_GPU_ARRAY_MEMBER
};

struct FrameSettings {
    bool jitter = true; ///< random point in each pixel; off = pixel centres
};

GpuSceneData convertScene(const Scene& scene, const FrameSettings& settings);

/// Materials of the dielectric spheres and boxes that contain the camera's
/// eye, outermost first (the medium stack a camera ray starts with).
std::vector<uint32_t> mediaAroundCamera(const Scene& scene);

/// Triangle lights that can emit: zero-area (degenerate) ones are dropped.
std::vector<TriangleLight> emittingTriangleLights(const Scene& scene);

/// Area of a triangle, computed in double.
double triangleArea(const std::array<glm::dvec3, 3>& v);

/// Workgroup tiles covering a width x height image.
uint32_t tileCountFor(uint32_t width, uint32_t height);
/// A stride coprime to tileCount that spreads consecutive workgroups over the image.
uint32_t tileStrideFor(uint32_t tileCount);

} // namespace vkrt
