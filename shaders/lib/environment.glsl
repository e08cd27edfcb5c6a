// Radiance arriving from infinitely far away: a constant colour or a cubemap.
#ifndef VKRT_ENVIRONMENT_GLSL
#define VKRT_ENVIRONMENT_GLSL

vec3 environmentRadiance(vec3 dir)
{
#ifdef VKRT_HAS_CUBEMAP
    return textureLod(environmentMap, dir, 0.0).rgb;
#else
    return u.backgroundColor;
#endif
}

#endif
