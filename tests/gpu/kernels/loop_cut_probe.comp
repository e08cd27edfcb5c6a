// The loop-cut fault's probe (gpu/spirv_fault_probe_test.cpp): outputs[i] =
// the passes a loop makes to inputs[i], then the passes of a second loop to
// inputs[i] (the two share the fault's count of loop-header entries).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint n = uint(inputs[i]), first = 0u, second = 0u;
    for (uint k = 0u; k < n; ++k)
        ++first;
    while (second < n)
        ++second;
    outputs[2u * i] = float(first);
    outputs[2u * i + 1u] = float(second);
}
