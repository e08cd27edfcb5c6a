// Invocation i evaluates lib/iridescence.glsl's iridescenceFresnel at
// (outsideIor, filmIor, cosTheta1, thicknessNm, baseF0.rgb) = inputs[7i .. 7i+6]:
// outputs[3i .. 3i+2] = its RGB (tests/gpu/iridescence_probe_test.cpp).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/iridescence.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint at = 7u * i;
    vec3 baseF0 = vec3(inputs[at + 4u], inputs[at + 5u], inputs[at + 6u]);
    vec3 f = iridescenceFresnel(inputs[at], inputs[at + 1u], inputs[at + 2u], inputs[at + 3u], baseF0);
    outputs[3u * i] = f.r;
    outputs[3u * i + 1u] = f.g;
    outputs[3u * i + 2u] = f.b;
}
