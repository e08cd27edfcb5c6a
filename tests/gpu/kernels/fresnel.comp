// Invocation i evaluates the Fresnel functions for (cosI, eta, ior) =
// inputs[3i .. 3i+2]: outputs[4i ..] = schlick(cosI, R0(ior)), exact,
// schlick-dielectric, and finite-check flag.
#version 460
#include "probe.glsl"
#include "lib/fresnel.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    float cosI = inputs[3 * i], eta = inputs[3 * i + 1], ior = inputs[3 * i + 2];
    outputs[4 * i + 0] = fresnelSchlick(cosI, schlickR0(ior));
    outputs[4 * i + 1] = fresnelExact(cosI, eta);
    outputs[4 * i + 2] = fresnelSchlickDielectric(cosI, eta, ior);
    outputs[4 * i + 3] = dielectricReflectance(FRESNEL_EXACT, cosI, eta, ior);
}
