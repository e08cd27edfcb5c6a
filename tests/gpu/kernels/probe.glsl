// Common interface of the test probe kernels (tests/support/ProbeKernel.h).
// Kernels enable GL_GOOGLE_include_directive before including this file.

#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer ProbeInput { float inputs[]; };
layout(std430, binding = 1) writeonly buffer ProbeOutput { float outputs[]; };
layout(push_constant) uniform ProbePush { uint invocationCount; };

#include "shared/SceneTypes.h"
#include "lib/ray.glsl"
