// pcg4d (lib/random.glsl) on inputs given as 16-bit halves so that no bit
// pattern travels as a float: inputs[8i ..] = (lo, hi) of v.x, v.y, v.z, v.w;
// outputs[8i ..] = (lo, hi) of each lane of pcg4d(v).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/random.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uvec4 v;
    for (int k = 0; k < 4; ++k)
        v[k] = uint(inputs[8u * i + 2u * uint(k)]) | (uint(inputs[8u * i + 2u * uint(k) + 1u]) << 16u);
    uvec4 h = pcg4d(v);
    for (int k = 0; k < 4; ++k) {
        outputs[8u * i + 2u * uint(k)] = float(h[k] & 0xffffu);
        outputs[8u * i + 2u * uint(k) + 1u] = float(h[k] >> 16u);
    }
}
