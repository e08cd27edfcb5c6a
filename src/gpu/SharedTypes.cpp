// Host-side checks of the GPU record layouts in shaders/shared. The kernels use
// the GLSL scalar block layout, in which every member here is aligned to 4
// bytes; C++ lays the same members out identically as long as no padding
// appears, which these asserts guarantee. tests/gpu/shared_layout_test.cpp
// compares every member offset with glslang's reflection.
#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

#include <cstddef>

namespace vkrt::gpu {

static_assert(alignof(vec3) == 4 && sizeof(vec3) == 12, "GLM vec3 must be three packed floats");
static_assert(sizeof(Material) == 52);
static_assert(sizeof(Sphere) == 20);
static_assert(sizeof(Box) == 28);
static_assert(sizeof(Triangle) == 40);
static_assert(sizeof(Plane) == 28);
static_assert(sizeof(PointLight) == 24);
static_assert(sizeof(TriangleLight) == 56);
static_assert(sizeof(SceneUniforms) == 120);
// Each uniform scene array fills at most the 16 KiB every Vulkan device allows.
constexpr uint32_t kUniformArrayBytes = 16384;
static_assert(UNIFORM_MATERIALS * sizeof(Material) <= kUniformArrayBytes && (UNIFORM_MATERIALS + 1) * sizeof(Material) > kUniformArrayBytes);
static_assert(UNIFORM_SPHERES * sizeof(Sphere) <= kUniformArrayBytes && (UNIFORM_SPHERES + 1) * sizeof(Sphere) > kUniformArrayBytes);
static_assert(UNIFORM_BOXES * sizeof(Box) <= kUniformArrayBytes && (UNIFORM_BOXES + 1) * sizeof(Box) > kUniformArrayBytes);
static_assert(UNIFORM_TRIANGLES * sizeof(Triangle) <= kUniformArrayBytes && (UNIFORM_TRIANGLES + 1) * sizeof(Triangle) > kUniformArrayBytes);
static_assert(UNIFORM_PLANES * sizeof(Plane) <= kUniformArrayBytes && (UNIFORM_PLANES + 1) * sizeof(Plane) > kUniformArrayBytes);
static_assert(UNIFORM_POINT_LIGHTS * sizeof(PointLight) <= kUniformArrayBytes && (UNIFORM_POINT_LIGHTS + 1) * sizeof(PointLight) > kUniformArrayBytes);
static_assert(UNIFORM_TRIANGLE_LIGHTS * sizeof(TriangleLight) <= kUniformArrayBytes && (UNIFORM_TRIANGLE_LIGHTS + 1) * sizeof(TriangleLight) > kUniformArrayBytes);
static_assert(MEDIUM_STACK_DEPTH == 4, "lib/media.glsl stores the stack in one uvec4");
static_assert(sizeof(FrameConstants) == 8);
static_assert(sizeof(AccumPixel) == 28);
static_assert(sizeof(RenderStats) == 8);
static_assert(sizeof(MomentPixel) == 36);
static_assert(offsetof(SceneUniforms, tileStride) == 92);
static_assert(offsetof(Material, fresnel) == 48);
static_assert(offsetof(TriangleLight, radiance) == 44);

} // namespace vkrt::gpu
