// Counter-based random numbers. Every draw hashes (pixel, frame, seed,
// dimension) with pcg4d (Jarzynski & Olano, "Hash Functions for GPU
// Rendering", JCGT 2020). pcg4d is a bijection on uvec4, so distinct
// (pixel, frame, seed, dimension) tuples never share an input, and no state
// is carried between frames: frame f's samples do not depend on frame f-1.
#ifndef VKRT_RANDOM_GLSL
#define VKRT_RANDOM_GLSL

#include "lib/pcg.glsl"

#ifdef VKRT_SAMPLER_SOBOL
// Owen-scrambled Sobol' points instead (`--sampler sobol`), same interface.
#include "lib/sobol.glsl"
#else
struct Sampler {
    uint pixelIndex;
    uint frameIndex;
    uint seed;
    uint dimension;
};

Sampler samplerCreate(uint pixelIndex, uint frameIndex, uint seed)
{
    return Sampler(pixelIndex, frameIndex, seed, 0u);
}

// 24 high bits -> [0, 1): exact in float32, never returns 1.
vec4 toUnitFloat(uvec4 bits) { return vec4(bits >> 8u) * (1.0 / 16777216.0); }

vec4 sampleNext4D(inout Sampler s)
{
    uvec4 bits = pcg4d(uvec4(s.pixelIndex, s.frameIndex, s.seed, s.dimension));
    s.dimension += 1u;
    return toUnitFloat(bits);
}

vec2 sampleNext2D(inout Sampler s) { return sampleNext4D(s).xy; }
float sampleNext1D(inout Sampler s) { return sampleNext4D(s).x; }

#endif // VKRT_SAMPLER_SOBOL

#endif
