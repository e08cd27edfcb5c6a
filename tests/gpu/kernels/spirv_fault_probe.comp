// The SPIR-V fault injector's probe (gpu/spirv_fault_probe_test.cpp):
// inputs[2i ..] = (x, y); outputs[4i ..] = (x * y, sqrt(x), min(x, y), max(x, y)).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    float x = inputs[2u * i], y = inputs[2u * i + 1u];
    outputs[4u * i] = x * y;
    outputs[4u * i + 1u] = sqrt(x);
    outputs[4u * i + 2u] = min(x, y);
    outputs[4u * i + 3u] = max(x, y);
}
