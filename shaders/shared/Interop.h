// Lets one header be compiled both as C++ (host) and as GLSL (kernels).
// In C++ the GLSL vector types alias GLM's, constants become constexpr and
// everything lives in namespace vkrt::gpu; in GLSL the macros vanish.
#ifndef VKRT_SHARED_INTEROP_H
#define VKRT_SHARED_INTEROP_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace vkrt::gpu {
using uint = uint32_t;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using uvec2 = glm::uvec2;
using uvec4 = glm::uvec4;
} // namespace vkrt::gpu
#define VKRT_BEGIN_NAMESPACE namespace vkrt::gpu {
#define VKRT_END_NAMESPACE }
#define VKRT_CONSTANT(type, name, value) inline constexpr type name = value;
#else
#define VKRT_BEGIN_NAMESPACE
#define VKRT_END_NAMESPACE
#define VKRT_CONSTANT(type, name, value) const type name = value;
#endif

#endif
