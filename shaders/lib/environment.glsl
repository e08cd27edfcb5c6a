// Radiance arriving from infinitely far away: a constant colour or a cubemap,
// and (path integrator with a cubemap) importance sampling of the cubemap.
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

#ifdef VKRT_ENVIRONMENT_SAMPLING
// Texels are chosen with probability proportional to luminance times solid
// angle (host: src/render/EnvironmentSampling.cpp), then a point uniformly
// inside the texel. Face conventions follow src/render/CubeFaces.h (Vulkan).

// Direction through face coordinates (s, t) in [0,1]^2, not normalized; its
// length r gives the texel's solid-angle density: d(omega) = 4 ds dt / r^3.
vec3 cubeFaceVector(uint face, vec2 st)
{
    float sc = 2.0 * st.x - 1.0, tc = 2.0 * st.y - 1.0;
    if (face == 0u) return vec3(1.0, -tc, -sc);
    if (face == 1u) return vec3(-1.0, -tc, sc);
    if (face == 2u) return vec3(sc, 1.0, tc);
    if (face == 3u) return vec3(sc, -1.0, -tc);
    if (face == 4u) return vec3(sc, -tc, 1.0);
    return vec3(-sc, -tc, -1.0);
}

// Face and (s, t) of a direction: the Vulkan cube map face selection.
uint cubeFaceOf(vec3 d, out vec2 st)
{
    vec3 a = abs(d);
    uint face;
    float sc, tc, ma;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x > 0.0 ? 0u : 1u;
        sc = d.x > 0.0 ? -d.z : d.z;
        tc = -d.y;
        ma = a.x;
    } else if (a.y >= a.z) {
        face = d.y > 0.0 ? 2u : 3u;
        sc = d.x;
        tc = d.y > 0.0 ? d.z : -d.z;
        ma = a.y;
    } else {
        face = d.z > 0.0 ? 4u : 5u;
        sc = d.z > 0.0 ? d.x : -d.x;
        tc = -d.y;
        ma = a.z;
    }
    st = clamp(0.5 * (vec2(sc, tc) / ma + 1.0), 0.0, 1.0);
    return face;
}

float texelProbability(uint index) { return environmentCdf[index + 1u] - environmentCdf[index]; }

// Solid-angle density of sampleEnvironment producing direction `dir`.
float environmentPdf(vec3 dir)
{
    vec2 st;
    uint face = cubeFaceOf(dir, st);
    uint n = u.environmentSize;
    uvec2 texel = min(uvec2(st * float(n)), uvec2(n - 1u));
    float p = texelProbability((face * n + texel.y) * n + texel.x);
    float r = length(cubeFaceVector(face, st));
    return p * float(n * n) * r * r * r * 0.25;
}

// First index i with cdf[i + 1] > u (binary search over 6 N^2 texels).
uint findTexel(float target)
{
    uint lo = 0u, hi = 6u * u.environmentSize * u.environmentSize;
    while (lo + 1u < hi) {
        ++g_loopIterations;
        uint mid = (lo + hi) / 2u;
        if (environmentCdf[mid] <= target) lo = mid;
        else hi = mid;
    }
    return lo;
}

// A direction drawn from the environment's texel distribution; pdf in solid angle.
vec3 sampleEnvironment(vec3 rnd, out float pdf)
{
    uint n = u.environmentSize;
    uint index = findTexel(rnd.x);
    uint face = index / (n * n), within = index % (n * n);
    vec2 st = (vec2(within % n, within / n) + rnd.yz) / float(n);
    vec3 v = cubeFaceVector(face, st);
    float r = length(v);
    pdf = texelProbability(index) * float(n * n) * r * r * r * 0.25;
    return v / r;
}
#endif

#endif
