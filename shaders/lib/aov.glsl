// Arbitrary output values (`vkrt render --aov`) in Open Image Denoise's
// conventions: the albedo and world-space shading normal of each sample's
// first non-specular surface (followed through perfect mirrors and glass),
// and the camera ray's first hit's depth and position. The integrators
// report what their paths meet; render.comp adds each accepted sample's
// values to the pixel's running means (shared/SceneTypes.h, AovPixel).
#ifndef VKRT_AOV_GLSL
#define VKRT_AOV_GLSL

#ifdef VKRT_AOV
struct AovSample {
    vec3 albedo;
    vec3 normal;
    vec3 position; // camera-relative
    float depth;   // along the viewing direction
    bool hit;      // the camera ray found a surface
    bool settled;  // albedo and normal are final
};

AovSample g_aov;

void aovStartSample() { g_aov = AovSample(vec3(0.0), vec3(0.0), vec3(0.0), 0.0, false, false); }

// The first surface along the camera ray (the integrators call this for
// every hit; only the first counts).
void aovSurfaceHit(SurfaceHit hit)
{
    if (g_aov.hit || g_aov.settled)
        return;
    g_aov.hit = true;
    g_aov.position = hit.position;
    g_aov.depth = dot(hit.position, u.cameraForward);
#ifdef VKRT_TEST_HIT_PROBE
    // Test hook (tests/render/accel_backends_test.cpp): the camera ray's
    // closest hit as the traversal found it, for a hit-for-hit comparison of
    // the backends at one sample per pixel: albedo = (kind, record,
    // primitive), exact as floats below 2^24; normal = (t, the length of the
    // hit point's error bound, |cos| of the incidence: a pinhole camera's
    // rays start at the camera-relative origin).
    g_aov.albedo = vec3(float(hit.shape), float(hit.index), float(hit.primitive));
    g_aov.normal = vec3(hit.t, length(hit.error), abs(dot(normalize(hit.position), hit.normal)));
    g_aov.settled = true;
#endif
}

// What a material reflects at normal incidence, as a denoiser's albedo:
// its colour, 1 for glass, a conductor's Fresnel reflectance times its tint.
vec3 materialAlbedo(Material m)
{
    if (m.type == MATERIAL_LAMBERT || m.type == MATERIAL_PLASTIC || m.type == MATERIAL_PBR)
        return m.diffuse;
    if (m.type == MATERIAL_PHONG)
        return min(m.diffuse + m.specular, vec3(1.0));
    if (m.type == MATERIAL_CONDUCTOR)
        return m.specular * fresnelConductor(1.0, m.eta, m.k);
    if (m.type == MATERIAL_DIELECTRIC || m.type == MATERIAL_ROUGH_DIELECTRIC)
        return vec3(1.0);
    return m.specular; // mirror, glossy
}

// A surface the path scatters from; the first that is not purely specular
// settles the albedo and normal.
void aovScatter(Material m, vec3 ns)
{
    if (g_aov.settled || scattersIntoDeltasOnly(m))
        return;
    g_aov.albedo = materialAlbedo(m);
    g_aov.normal = ns;
    g_aov.settled = true;
}

// The path found a light or escaped before a non-specular surface: albedo
// and normal stay zero.
void aovEnd() { g_aov.settled = true; }

// Adds the finished sample to the pixel's running means; `count` is the
// pixel's number of accepted samples including this one.
void accumulateAov(uint slot, uint count)
{
    AovPixel a = aovs[slot];
    float weight = 1.0 / float(count);
    a.albedo += (g_aov.albedo - a.albedo) * weight;
    a.normal += (g_aov.normal - a.normal) * weight;
    if (g_aov.hit) {
        a.hits += 1u;
        float hitWeight = 1.0 / float(a.hits);
        a.position += (g_aov.position - a.position) * hitWeight;
        a.depth += (g_aov.depth - a.depth) * hitWeight;
    }
    aovs[slot] = a;
}
#else
void aovStartSample() {}
void aovSurfaceHit(SurfaceHit hit) {}
void aovScatter(Material m, vec3 ns) {}
void aovEnd() {}
#endif

#endif
