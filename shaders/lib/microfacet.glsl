// The GGX (Trowbridge-Reitz) microfacet distribution in a local frame whose
// z axis is the shading normal, with Smith's separable masking-shadowing
// G(wo, wi, m) = G1(wo, m) G1(wi, m) (what Mitsuba 3 uses), and Heitz's
// sampling of the normals visible from a direction ("Sampling the GGX
// Distribution of Visible Normals", JCGT 7(4), 2018). alpha = roughness^2,
// per tangent axis; callers keep it at or above MIN_GGX_ALPHA.
// The conductor and dielectric Fresnel terms of the rough materials are here
// too. tests/material and tests/gpu check all of it against the double-
// precision references of tests/support/ReferenceBsdf.h.
#ifndef VKRT_MICROFACET_GLSL
#define VKRT_MICROFACET_GLSL

struct LocalFrame {
    vec3 t;
    vec3 b;
    vec3 n;
};

// The frame of the anisotropic axes: Duff et al.'s basis around n (its
// tangent turns with n continuously except at n = -z).
LocalFrame frameAround(vec3 n)
{
    LocalFrame f;
    f.n = n;
    orthonormalBasis(n, f.t, f.b);
    return f;
}

vec3 toFrame(LocalFrame f, vec3 w) { return vec3(dot(w, f.t), dot(w, f.b), dot(w, f.n)); }
vec3 fromFrame(LocalFrame f, vec3 w) { return w.x * f.t + w.y * f.b + w.z * f.n; }

// D(m) for m.z > 0; 0 below.
float ggxD(vec3 m, vec2 alpha)
{
    if (m.z <= 0.0)
        return 0.0;
    vec2 s = m.xy / alpha;
    float e = dot(s, s) + m.z * m.z;
    return 1.0 / (PI * alpha.x * alpha.y * e * e);
}

// Smith's Lambda(w), written as 2 / (1 + sqrt(1 + a^2 tan^2)) so that it has
// no cancellation near normal incidence.
float ggxG1Of(vec3 w, vec2 alpha)
{
    float z2 = w.z * w.z;
    vec2 aw = alpha * w.xy;
    float a2tan2 = dot(aw, aw) / max(z2, 1e-30);
    return 2.0 / (1.0 + sqrt(1.0 + a2tan2));
}

// Smith's Lambda(w) = (sqrt(1 + a^2 tan^2) - 1) / 2, written without the
// cancellation near normal incidence (the height-correlated G of the pbr material).
float ggxLambdaOf(vec3 w, vec2 alpha)
{
    vec2 aw = alpha * w.xy;
    float a2tan2 = dot(aw, aw) / max(w.z * w.z, 1e-30);
    return 0.5 * a2tan2 / (1.0 + sqrt(1.0 + a2tan2));
}

// G1(w, m): 0 when w sees the back of the microfacet.
float ggxG1(vec3 w, vec3 m, vec2 alpha)
{
    if (dot(w, m) * w.z <= 0.0)
        return 0.0;
    return ggxG1Of(w, alpha);
}

// A normal m drawn from D_wo(m) = G1(wo, m) max(0, wo.m) D(m) / wo.z (wo.z > 0).
vec3 sampleGgxVisibleNormal(vec3 wo, vec2 alpha, vec2 u)
{
    // The view direction in the stretched, hemispherical configuration.
    vec3 vh = normalize(vec3(alpha * wo.xy, wo.z));
    float lensq = dot(vh.xy, vh.xy);
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    // A point on the projected disk, squeezed towards the visible half.
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    // Back to the ellipsoid.
    return normalize(vec3(alpha * nh.xy, max(1e-7, nh.z)));
}

// Density of sampleGgxVisibleNormal's reflected direction about m = h:
// D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z).
float ggxReflectionPdf(vec3 wo, vec3 h, vec2 alpha)
{
    return ggxG1(wo, h, alpha) * ggxD(h, alpha) / (4.0 * wo.z);
}

// Exact unpolarized Fresnel reflectance of a conductor with complex index
// eta + i k, light arriving from a medium of index 1 (per channel).
vec3 fresnelConductor(float cosI, vec3 eta, vec3 k)
{
    float c = clamp(cosI, 0.0, 1.0);
    float c2 = c * c;
    float s2 = 1.0 - c2;
    vec3 t0 = eta * eta - k * k - vec3(s2);
    vec3 a2b2 = sqrt(t0 * t0 + 4.0 * eta * eta * k * k);
    vec3 a = sqrt(max(vec3(0.0), 0.5 * (a2b2 + t0)));
    vec3 t1 = a2b2 + vec3(c2);
    vec3 t2 = 2.0 * c * a;
    vec3 rs = (t1 - t2) / (t1 + t2);
    vec3 t3 = c2 * a2b2 + vec3(s2 * s2);
    vec3 t4 = t2 * s2;
    vec3 rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5 * (rs + rp);
}

#endif
