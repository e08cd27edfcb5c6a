// Invocation i refracts direction -wo at a surface with outward
// normal n through sampleDielectric with u = 1 (always the refracted branch
// unless total internal reflection): inputs[7i ..] = wo.xyz, n.xyz, ior; the
// surface is hit from outside when dot(wo, n) > 0. outputs[4i ..] = dir.xyz,
// transmitted flag.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#define VKRT_MATERIAL_DIELECTRIC 1
#include "lib/fresnel.glsl"
#include "lib/sampling.glsl"
#include "lib/microfacet.glsl"
#include "lib/bsdf.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    vec3 wo = vec3(inputs[7 * i], inputs[7 * i + 1], inputs[7 * i + 2]);
    vec3 outward = vec3(inputs[7 * i + 3], inputs[7 * i + 4], inputs[7 * i + 5]);
    Material m;
    m.ior = inputs[7 * i + 6];
    m.fresnel = FRESNEL_EXACT;
    m.type = MATERIAL_DIELECTRIC;
    bool frontFace = dot(wo, outward) > 0.0;
    vec3 n = frontFace ? outward : -outward;
    BsdfSample s = sampleDielectric(m, n, wo, frontFace ? 1.0 / m.ior : m.ior, vec3(1.0));
    outputs[4 * i + 0] = s.dir.x;
    outputs[4 * i + 1] = s.dir.y;
    outputs[4 * i + 2] = s.dir.z;
    outputs[4 * i + 3] = s.transmitted ? 1.0 : 0.0;
}
