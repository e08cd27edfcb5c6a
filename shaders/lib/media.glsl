// The dielectrics a ray is inside, innermost last, so that every interface
// bends light by the ratio of the indices on its two sides: a sphere inside a
// sphere of the same index is invisible, two coincident spheres act as one,
// and a camera inside glass starts inside it. Entering a dielectric pushes its
// material; leaving removes the innermost entry of that material (entries of
// one material are interchangeable). The current medium is the top entry
// ("last entered wins" where objects overlap). Air (index 1, no absorption)
// when empty.
#ifndef VKRT_MEDIA_GLSL
#define VKRT_MEDIA_GLSL

struct MediumStack {
    uint count;
    uvec4 interiors; // MEDIUM_STACK_DEPTH entries: the materials, innermost last
    // The products of n_incident (x) and n_transmitted (y) over the
    // refractions that brought the ray here. Radiance scales by
    // (n_incident / n_transmitted)^2 at a refraction (the beam's solid angle
    // changes), so a path's samples carry (x / y)^2: see radianceScale.
    vec2 refractedIndices;
};

// The stack the camera starts in (found by the host, innermost last).
MediumStack cameraMedia()
{
    return MediumStack(min(u.cameraMediumCount, MEDIUM_STACK_DEPTH), u.cameraMedia, vec2(1.0));
}

#if defined(VKRT_MATERIAL_DIELECTRIC) || defined(VKRT_MATERIAL_ROUGH_DIELECTRIC) || defined(VKRT_PBR_TRANSMISSION)
float mediumIor(MediumStack s) { return s.count == 0u ? 1.0 : materials[s.interiors[s.count - 1u]].ior; }

vec3 mediumAbsorption(MediumStack s)
{
    return s.count == 0u ? vec3(0.0) : materials[s.interiors[s.count - 1u]].absorption;
}

// The stack on the far side of an interface of `material`. A full stack
// ignores one more level; leaving a material that is not on the stack (the
// ray started inside it unnoticed) changes nothing.
MediumStack crossInterface(MediumStack s, uint material, bool entering)
{
    if (entering) {
        if (s.count < MEDIUM_STACK_DEPTH) {
            s.interiors[s.count] = material;
            s.count += 1u;
        }
        return s;
    }
    // Remove the innermost entry of `material`, written out over the fixed
    // depth so no loop counts against lavapipe's loop budget.
    int found = -1;
    if (s.count > 0u && s.interiors[0] == material) found = 0;
    if (s.count > 1u && s.interiors[1] == material) found = 1;
    if (s.count > 2u && s.interiors[2] == material) found = 2;
    if (s.count > 3u && s.interiors[3] == material) found = 3;
    if (found < 0)
        return s;
    if (found <= 0) s.interiors[0] = s.interiors[1];
    if (found <= 1) s.interiors[1] = s.interiors[2];
    if (found <= 2) s.interiors[2] = s.interiors[3];
    s.count -= 1u;
    return s;
}

bool onStack(MediumStack s, uint material)
{
    return (s.count > 0u && s.interiors[0] == material) || (s.count > 1u && s.interiors[1] == material) ||
           (s.count > 2u && s.interiors[2] == material) || (s.count > 3u && s.interiors[3] == material);
}

// The stack as it stands at a surface, before its crossing. A ray that meets
// the front of a mesh is outside that mesh, whatever the stack says: a mesh
// need not be closed, and a ray that entered it and left through a hole (the
// Stanford bunny's base) crossed no surface on the way out. Its stale entry
// goes here, so the front is crossed from the medium around the mesh, as
// Mitsuba does by the side alone; otherwise the ray would find glass on both
// sides and pass the front unbent and unreflected.
MediumStack mediaAtSurface(MediumStack s, SurfaceHit hit)
{
#ifdef VKRT_HAS_MESHES
    if (hit.shape == SHAPE_MESH && hit.front && onStack(s, hit.material))
        return crossInterface(s, hit.material, false);
#endif
    return s;
}

// (n_incident, n_transmitted) at a surface hit. A mesh need not be closed:
// a ray can meet the back of a glass mesh without having entered it
// (through a hole, as in the Stanford bunny). Like Mitsuba, which decides
// at each interface by its side alone, such a surface is crossed as if the
// ray had been inside: from the material's index into the current medium.
vec2 surfaceIndices(MediumStack s, SurfaceHit hit)
{
#ifdef VKRT_HAS_MESHES
    if (hit.shape == SHAPE_MESH && !hit.front && !onStack(s, hit.material))
        return vec2(materials[hit.material].ior, mediumIor(s));
#endif
    float inside = mediumIor(s);
    float beyond = hit.front ? materials[hit.material].ior : mediumIor(crossInterface(s, hit.material, false));
    return vec2(inside, beyond);
}

// n_incident / n_transmitted at a surface hit.
float surfaceEta(MediumStack s, SurfaceHit hit)
{
    vec2 n = surfaceIndices(s, hit);
    return n.x / n.y;
}

// The stack beyond a surface the ray refracts through. The index products
// are rescaled by a power of two each time (exact), so they never overflow,
// and a path that returns to the medium it started in through interfaces
// whose sides agree (glass entered, then left) has x == y exactly: its
// samples are unscaled to the last bit. Where the sides disagree (an open
// mesh entered by its front and left through a hole), the factor is what
// Mitsuba's dielectric applies crossing by crossing.
MediumStack refractThrough(MediumStack s, SurfaceHit hit)
{
    vec2 crossed = s.refractedIndices * surfaceIndices(s, hit);
    int exponent;
    frexp(crossed.y, exponent);
    s = crossInterface(s, hit.material, hit.front);
    s.refractedIndices = ldexp(crossed, ivec2(-exponent));
    return s;
}

// The factor a sample's radiance carries for the refractions behind it:
// (n_incident / n_transmitted)^2 over them, 1 for a path that is back in the
// medium it started in (the usual case: camera and lights in air).
float radianceScale(MediumStack s)
{
    float ratio = s.refractedIndices.x / s.refractedIndices.y;
    return ratio * ratio;
}
#else
// Without dielectrics or volumetric pbr materials a ray is always in air.
vec3 mediumAbsorption(MediumStack s) { return vec3(0.0); }
MediumStack crossInterface(MediumStack s, uint material, bool entering) { return s; }
MediumStack mediaAtSurface(MediumStack s, SurfaceHit hit) { return s; }
float surfaceEta(MediumStack s, SurfaceHit hit) { return 1.0; }
MediumStack refractThrough(MediumStack s, SurfaceHit hit) { return s; }
float radianceScale(MediumStack s) { return 1.0; }
#endif

// What a sample adds for radiance L arriving at the end of a path with this
// throughput: sampleWeight * L, bit for bit throughput * L when the scale
// is 1.
vec3 sampleWeight(vec3 throughput, MediumStack media) { return throughput * radianceScale(media); }

#endif
