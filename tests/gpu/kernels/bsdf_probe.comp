// The microfacet BSDFs of lib/bsdf.glsl in the local frame (n = +z), for the
// sampling-density and energy tests of tests/gpu/microfacet_probe_test.cpp.
// inputs[0 .. 24]: one Material, member by member in the order of
// shared/SceneTypes.h (uints as float values); inputs[25 .. 27]: wo;
// inputs[28]: eta (n_i / n_t of the interface); inputs[29]: mode;
// inputs[30]: seed; inputs[64 ..]: a rough plastic's coating table
// (Material::table = 64 points here). Mode 0, invocation i: one sample with
// uniforms from pcg4d(i, seed): outputs[8i ..] = dir.xyz, weight.xyz,
// pdfBsdf(dir) (reflection only; 0 for transmitted and delta samples),
// flags (1 specular, 2 transmitted, 4 no sample). Mode 1: evaluates at
// wi = inputs[128 + 3i ..]: outputs[8i ..] = evalBsdf(wi).xyz, pdfBsdf(wi).
// With VKRT_PBR_LAYERS defined (tests/gpu/pbr_layers_probe_test.cpp): the pbr
// layers at inputs[31 .. 37] (sheenColor, sheenRoughness, specularFactor,
// clearcoat, clearcoatAlpha), the sheen table at inputs[128 ..] (Material::table
// = 128) and mode 1's directions after it, at inputs[kDirectionsAt ..]; as a
// hit resolves them (lib/material_textures.glsl), the anisotropy's direction
// at inputs[40 .. 42] (VKRT_PBR_ANISOTROPY; alphaX its stretched alpha) and the
// coat's normal at inputs[43 .. 45] (zero: n).
// With VKRT_PBR_TRANSMISSION also (tests/gpu/pbr_transmission_probe_test.cpp):
// m.transmission at inputs[38], m.pbrFlags at inputs[39] (PBR_FLAG_VOLUME for
// a volume's boundary). A volume's interface eta, m.exponent, is inputs[28]:
// withInterfaceEta puts it there as the integrators do (lib/path.glsl), and
// sampleBsdf gets the same eta.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#define VKRT_MATERIAL_CONDUCTOR 1
#define VKRT_MATERIAL_ROUGH_DIELECTRIC 1
#define VKRT_MATERIAL_PLASTIC 1
#define VKRT_MATERIAL_PBR 1
#define VKRT_HAS_MATERIAL_TABLES 1
#define materialTables inputs
#include "lib/pcg.glsl"
#include "lib/fresnel.glsl"
#include "lib/sampling.glsl"
#include "lib/microfacet.glsl"
#include "lib/bsdf.glsl"

#ifdef VKRT_PBR_LAYERS
const uint kDirectionsAt = 128u + SHEEN_TABLE_SIDE * SHEEN_TABLE_SIDE;
#else
const uint kDirectionsAt = 128u;
#endif

Material probeMaterial()
{
    Material m;
    m.diffuse = vec3(inputs[0], inputs[1], inputs[2]);
    m.type = uint(inputs[3]);
    m.specular = vec3(inputs[4], inputs[5], inputs[6]);
    m.exponent = inputs[7];
    m.absorption = vec3(inputs[8], inputs[9], inputs[10]);
    m.ior = inputs[11];
    m.fresnel = uint(inputs[12]);
    m.alphaX = inputs[13];
    m.alphaY = inputs[14];
    m.table = inputs[15] < 0.0 ? NO_MATERIAL_TABLE : uint(inputs[15]);
    m.eta = vec3(inputs[16], inputs[17], inputs[18]);
    m.metallic = inputs[19];
    m.k = vec3(inputs[20], inputs[21], inputs[22]);
    m.lobeWeight = inputs[23];
    m.internalReflectance = inputs[24];
#ifdef VKRT_PBR_LAYERS
    m.sheenColor = vec3(inputs[31], inputs[32], inputs[33]);
    m.sheenRoughness = inputs[34];
    m.specularFactor = inputs[35];
    m.clearcoat = inputs[36];
    m.clearcoatAlpha = inputs[37];
    m.anisotropy = vec3(inputs[40], inputs[41], inputs[42]);
    m.clearcoatNormal = vec3(inputs[43], inputs[44], inputs[45]);
#endif
#ifdef VKRT_PBR_TRANSMISSION
    m.transmission = inputs[38];
    m.pbrFlags = uint(inputs[39]);
#endif
    return m;
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    Material m = probeMaterial();
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec3 wo = vec3(inputs[25], inputs[26], inputs[27]);
    float eta = inputs[28];
#ifdef VKRT_MATERIAL_ROUGH_DIELECTRIC
    m = withInterfaceEta(m, eta);
#endif
    if (inputs[29] == 0.0) {
        uvec4 bits = pcg4d(uvec4(i, uint(inputs[30]), 0x9e3779b9u, 7u));
        vec3 u = vec3(bits.xyz >> 8u) * (1.0 / 16777216.0);
        float sampledPdf;
        BsdfSample s = sampleBsdfWeighted(m, n, wo, eta, u, false, sampledPdf);
        bool none = s.weight == vec3(0.0);
        float pdf = (none || s.specular || s.transmitted) ? 0.0 : pdfBsdf(m, n, wo, s.dir);
        outputs[8 * i + 0] = s.dir.x;
        outputs[8 * i + 1] = s.dir.y;
        outputs[8 * i + 2] = s.dir.z;
        outputs[8 * i + 3] = s.weight.x;
        outputs[8 * i + 4] = s.weight.y;
        outputs[8 * i + 5] = s.weight.z;
        outputs[8 * i + 6] = pdf;
        outputs[8 * i + 7] = float((s.specular ? 1u : 0u) | (s.transmitted ? 2u : 0u) | (none ? 4u : 0u));
    } else {
        vec3 wi = vec3(inputs[kDirectionsAt + 3u * i], inputs[kDirectionsAt + 3u * i + 1u],
                       inputs[kDirectionsAt + 3u * i + 2u]);
        vec3 f = evalBsdf(m, n, wo, wi);
        outputs[8 * i + 0] = f.x;
        outputs[8 * i + 1] = f.y;
        outputs[8 * i + 2] = f.z;
        outputs[8 * i + 3] = pdfBsdf(m, n, wo, wi);
    }
}
