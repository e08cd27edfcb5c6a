// Resource declarations of the render kernels. Each scene buffer exists only
// in the variants whose FeatureSet needs it (src/scene/FeatureSet.cpp), and the
// host builds the descriptor set layout from the same list.
#ifndef VKRT_BINDINGS_GLSL
#define VKRT_BINDINGS_GLSL

#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

layout(scalar, binding = BINDING_UNIFORMS) uniform UniformBlock { SceneUniforms u; };
layout(scalar, binding = BINDING_ACCUMULATION) buffer AccumBlock { AccumPixel accum[]; };
layout(scalar, binding = BINDING_STATS) buffer StatsBlock { RenderStats stats; };
layout(push_constant, scalar) uniform PushBlock { FrameConstants frame; };
#ifdef VKRT_VARIANCE
layout(scalar, binding = BINDING_MOMENTS) buffer MomentBlock { MomentPixel moments[]; };
#endif

#ifdef VKRT_HAS_MATERIALS
layout(scalar, binding = BINDING_MATERIALS) readonly buffer MaterialBlock { Material materials[]; };
#endif
#ifdef VKRT_HAS_SPHERES
layout(scalar, binding = BINDING_SPHERES) readonly buffer SphereBlock { Sphere spheres[]; };
#endif
#ifdef VKRT_HAS_BOXES
layout(scalar, binding = BINDING_BOXES) readonly buffer BoxBlock { Box boxes[]; };
#endif
#ifdef VKRT_HAS_TRIANGLES
layout(scalar, binding = BINDING_TRIANGLES) readonly buffer TriangleBlock { Triangle triangles[]; };
#endif
#ifdef VKRT_HAS_PLANES
layout(scalar, binding = BINDING_PLANES) readonly buffer PlaneBlock { Plane planes[]; };
#endif
#ifdef VKRT_HAS_POINT_LIGHTS
layout(scalar, binding = BINDING_POINT_LIGHTS) readonly buffer PointLightBlock { PointLight pointLights[]; };
#endif
#ifdef VKRT_HAS_CUBEMAP
layout(binding = BINDING_ENVIRONMENT) uniform samplerCube environmentMap;
#endif
#ifdef VKRT_ENVIRONMENT_SAMPLING
layout(scalar, binding = BINDING_ENVIRONMENT_CDF) readonly buffer EnvironmentCdfBlock { float environmentCdf[]; };
#endif
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
layout(scalar, binding = BINDING_TRIANGLE_LIGHTS) readonly buffer TriangleLightBlock { TriangleLight triangleLights[]; };
#endif

#endif
