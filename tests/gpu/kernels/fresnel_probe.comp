// Invocation i evaluates the Fresnel functions for (cosI, eta, ior) =
// inputs[3i .. 3i+2]: outputs[6i ..] = fresnelSchlick(cosI, schlickR0(ior)),
// fresnelExact, fresnelSchlickDielectric, dielectricReflectance with
// FRESNEL_EXACT and with FRESNEL_SCHLICK, schlickR0(ior).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/fresnel.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    float cosI = inputs[3 * i], eta = inputs[3 * i + 1], ior = inputs[3 * i + 2];
    outputs[6 * i + 0] = fresnelSchlick(cosI, schlickR0(ior));
    outputs[6 * i + 1] = fresnelExact(cosI, eta);
    outputs[6 * i + 2] = fresnelSchlickDielectric(cosI, eta);
    outputs[6 * i + 3] = dielectricReflectance(FRESNEL_EXACT, cosI, eta);
    outputs[6 * i + 4] = dielectricReflectance(FRESNEL_SCHLICK, cosI, eta);
    outputs[6 * i + 5] = schlickR0(ior);
}
