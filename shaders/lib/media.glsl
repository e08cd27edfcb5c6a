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
    uvec4 materials; // MEDIUM_STACK_DEPTH entries
};

// The stack the camera starts in (found by the host, innermost last).
MediumStack cameraMedia() { return MediumStack(min(u.cameraMediumCount, MEDIUM_STACK_DEPTH), u.cameraMedia); }

#if defined(VKRT_MATERIAL_DIELECTRIC) || defined(VKRT_MATERIAL_ROUGH_DIELECTRIC)
float mediumIor(MediumStack s) { return s.count == 0u ? 1.0 : materials[s.materials[s.count - 1u]].ior; }

vec3 mediumAbsorption(MediumStack s)
{
    return s.count == 0u ? vec3(0.0) : materials[s.materials[s.count - 1u]].absorption;
}

// The stack on the far side of an interface of `material`. A full stack
// ignores one more level; leaving a material that is not on the stack (the
// ray started inside it unnoticed) changes nothing.
MediumStack crossInterface(MediumStack s, uint material, bool entering)
{
    if (entering) {
        if (s.count < MEDIUM_STACK_DEPTH) {
            s.materials[s.count] = material;
            s.count += 1u;
        }
        return s;
    }
    // Remove the innermost entry of `material`, written out over the fixed
    // depth so no loop counts against lavapipe's loop budget.
    int found = -1;
    if (s.count > 0u && s.materials[0] == material) found = 0;
    if (s.count > 1u && s.materials[1] == material) found = 1;
    if (s.count > 2u && s.materials[2] == material) found = 2;
    if (s.count > 3u && s.materials[3] == material) found = 3;
    if (found < 0)
        return s;
    if (found <= 0) s.materials[0] = s.materials[1];
    if (found <= 1) s.materials[1] = s.materials[2];
    if (found <= 2) s.materials[2] = s.materials[3];
    s.count -= 1u;
    return s;
}

// n_incident / n_transmitted for crossing an interface of `material`.
float interfaceEta(MediumStack s, uint material, bool entering)
{
    float inside = mediumIor(s);
    float beyond = entering ? materials[material].ior : mediumIor(crossInterface(s, material, false));
    return inside / beyond;
}
bool onStack(MediumStack s, uint material)
{
    return (s.count > 0u && s.materials[0] == material) || (s.count > 1u && s.materials[1] == material) ||
           (s.count > 2u && s.materials[2] == material) || (s.count > 3u && s.materials[3] == material);
}

// n_incident / n_transmitted at a surface hit. A mesh need not be closed:
// a ray can meet the back of a glass mesh without having entered it
// (through a hole, as in the Stanford bunny). Like Mitsuba, which decides
// at each interface by its side alone, such a surface is crossed as if the
// ray had been inside: from the material's index into the current medium.
float surfaceEta(MediumStack s, SurfaceHit hit)
{
#ifdef VKRT_HAS_MESHES
    if (hit.shape == SHAPE_MESH && !hit.front && !onStack(s, hit.material))
        return materials[hit.material].ior / mediumIor(s);
#endif
    return interfaceEta(s, hit.material, hit.front);
}
#else
// Without dielectrics a ray is always in air.
vec3 mediumAbsorption(MediumStack s) { return vec3(0.0); }
MediumStack crossInterface(MediumStack s, uint material, bool entering) { return s; }
float interfaceEta(MediumStack s, uint material, bool entering) { return 1.0; }
float surfaceEta(MediumStack s, SurfaceHit hit) { return 1.0; }
#endif

#endif
