// The Sobol' sampler (lib/sobol.glsl), or with VKRT_PROBE_PCG the pcg4d one
// (lib/random.glsl) through the same API. All integers travel as 16-bit halves
// so that no bit pattern passes through a float. inputs[0] is the mode:
//  0 records: inputs[1 + 7i ..] = pixel lo, hi, frame lo, hi, seed lo, hi,
//    first draw; outputs[16i ..] = four sampleNext4D draws from that draw on.
//  1 grid: inputs[1 ..] = frames, seed, first pixel; invocation i is frame
//    i % frames of pixel first + i / frames; outputs[16i ..] = its first four
//    sampleNext4D draws.
//  2 unscrambled (Sobol' only): inputs[1] = stride; outputs[8i ..] = lo, hi
//    of each dimension of sobolPoint4D(i * stride).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#ifdef VKRT_PROBE_PCG
#include "lib/random.glsl"
#else
#include "lib/sobol.glsl"
#endif

uint inputWord(uint at) { return uint(inputs[at]) | (uint(inputs[at + 1u]) << 16u); }

void writeDraws(uint at, inout Sampler s)
{
    for (uint d = 0u; d < 4u; ++d) {
        vec4 u4 = sampleNext4D(s);
        for (uint k = 0u; k < 4u; ++k) outputs[at + 4u * d + k] = u4[k];
    }
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint mode = uint(inputs[0]);
    if (mode == 0u) {
        uint at = 1u + 7u * i;
        Sampler s = samplerCreate(inputWord(at), inputWord(at + 2u), inputWord(at + 4u));
        s.dimension = uint(inputs[at + 6u]);
        writeDraws(16u * i, s);
    } else if (mode == 1u) {
        uint frames = uint(inputs[1]);
        Sampler s = samplerCreate(uint(inputs[3]) + i / frames, i % frames, uint(inputs[2]));
        writeDraws(16u * i, s);
    }
#ifndef VKRT_PROBE_PCG
    else if (mode == 2u) {
        uvec4 x = sobolPoint4D(i * uint(inputs[1]));
        for (uint k = 0u; k < 4u; ++k) {
            outputs[8u * i + 2u * k] = float(x[k] & 0xffffu);
            outputs[8u * i + 2u * k + 1u] = float(x[k] >> 16u);
        }
    }
#endif
}
