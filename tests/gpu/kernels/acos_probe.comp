// accurateAcos (lib/sampling.glsl) on the test GPU: outputs[i] = accurateAcos(inputs[i]).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/sampling.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    outputs[i] = accurateAcos(inputs[i]);
}
