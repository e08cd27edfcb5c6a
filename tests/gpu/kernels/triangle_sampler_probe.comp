// Invocation i draws one point on the triangle inputs[0..8]
// with the render kernels' sampler (pixel i, frame 0, seed inputs[9]) and
// sampleTriangle: outputs[3i ..] = p.xyz.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/random.glsl"
#include "lib/sampling.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    vec3 a = vec3(inputs[0], inputs[1], inputs[2]);
    vec3 b = vec3(inputs[3], inputs[4], inputs[5]);
    vec3 c = vec3(inputs[6], inputs[7], inputs[8]);
    Sampler rng = samplerCreate(i, 0u, uint(inputs[9]));
    vec3 p = sampleTriangle(a, b, c, sampleNext2D(rng));
    outputs[3 * i + 0] = p.x;
    outputs[3 * i + 1] = p.y;
    outputs[3 * i + 2] = p.z;
}
