// pcg4d (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020):
// a bijection on uvec4, shared by both samplers (lib/random.glsl, lib/sobol.glsl).
#ifndef VKRT_PCG_GLSL
#define VKRT_PCG_GLSL

uvec4 pcg4d(uvec4 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v.w += v.y * v.z;
    return v;
}

#endif
