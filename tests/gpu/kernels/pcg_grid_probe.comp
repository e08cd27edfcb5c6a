// pcg4d (lib/random.glsl) over every frame of one pixel per invocation, each
// output mapped back through the inverse of pcg4d (written out here step by
// step; tests/gpu/rng_test.cpp holds the same inverse in C++ and checks it).
// inputs = frames, seed, dimension, low and high 16 bits of the inverse of
// pcg4d's multiplier. Invocation i is pixel i; outputs[3i ..] = how many of its
// frames did not map back to (i, frame, seed, dimension), and the low and high
// 16 bits of the xor of every lane of every output (a checksum of pcg4d).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/random.glsl"

uvec4 unmix(uvec4 v)
{
    v.w -= v.y * v.z;
    v.z -= v.x * v.y;
    v.y -= v.z * v.x;
    v.x -= v.y * v.w;
    return v;
}

uvec4 pcg4dInverse(uvec4 v, uint multiplierInverse)
{
    v = unmix(v);
    v ^= v >> 16u;
    v = unmix(v);
    return (v - 1013904223u) * multiplierInverse;
}

void main()
{
    uint pixel = gl_GlobalInvocationID.x;
    if (pixel >= invocationCount)
        return;
    uint frames = uint(inputs[0]);
    uint seed = uint(inputs[1]);
    uint dimension = uint(inputs[2]);
    uint multiplierInverse = uint(inputs[3]) | (uint(inputs[4]) << 16u);
    uint mismatches = 0u;
    uint checksum = 0u;
    for (uint frame = 0u; frame < frames; ++frame) {
        uvec4 v = uvec4(pixel, frame, seed, dimension);
        uvec4 h = pcg4d(v);
        checksum ^= h.x ^ h.y ^ h.z ^ h.w;
        if (pcg4dInverse(h, multiplierInverse) != v)
            ++mismatches;
    }
    outputs[3u * pixel] = float(mismatches);
    outputs[3u * pixel + 1u] = float(checksum & 0xffffu);
    outputs[3u * pixel + 2u] = float(checksum >> 16u);
}
