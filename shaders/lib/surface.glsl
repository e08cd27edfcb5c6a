// What every shape and light kind shares: the hit a query finds (HitId), the
// surface point it describes (SurfaceHit), and the per-kind record loops,
// written once. Each kind's own file (lib/shapes/*.glsl, lib/lights/*.glsl)
// provides, named after its registry Type (shared/Kinds.h):
//   hitOneType(Ray, TriangleRay, uint i, bool anyHit, float tMax, inout HitId)
//       whether record i is hit before tMax; if so (and !anyHit) it is
//       written to the HitId. A kind the variant lacks returns false.
//   closestType / anyHitType   from VKRT_RECORD_LOOPS, or VKRT_NO_RECORDS
//       when the variant lacks the kind (or it has no area, as a point light);
//   describeType(Ray, HitId, inout SurfaceHit)  the hit's surface point.
// lib/scene.glsl expands the registry over them, so a kind without one of
// these functions does not compile.
// All loops count into g_loopIterations so the kernel can prove it stayed
// within lavapipe's per-invocation loop budget (shared/Bindings.h).
#ifndef VKRT_SURFACE_GLSL
#define VKRT_SURFACE_GLSL

uint g_loopIterations = 0u;

// HitId::shape: a registry kind's HIT_Type code (shared/Kinds.h: the SHAPE_*
// kinds, then SHAPE_LIGHT + a LIGHT_* kind for a light, black, emitting and
// opaque), or SHAPE_NONE.
const int SHAPE_NONE = -1;
const int SHAPE_LIGHT = SHAPE_KIND_COUNT;

const uint NO_EMITTER = 0xffffffffu;

struct SurfaceHit {
    float t;
    vec3 position;
    vec3 error;  // bound on |position - exact point| per coordinate (offsetRayOrigin)
    vec3 normal;  // unit geometric normal; outward for spheres and boxes
    vec3 shading; // unit shading normal, on the side of `normal` (meshes with vertex normals; else = normal)
    bool front;   // the ray arrived on the side `normal` points to
    uint material;
    int shape;
    uint index;
    uint emitter; // the Emitter this surface is (triangle lights, emissive meshes), else NO_EMITTER
#ifdef VKRT_HAS_TEXTURES
    // Texture coordinates (docs/scene-format.md, "Texture coordinates"), the
    // uv area per world area there (the ray cone's texel density), and the
    // world direction of increasing u with the bitangent's handedness
    // (bitangent = tangent.w cross(shading, tangent.xyz)) for normal maps.
    vec2 uv;
    float uvDensity;
    vec4 tangent;
#endif
#ifdef VKRT_HAS_MESH_UVS1
    vec2 uv1; // a mesh's second set (glTF TEXCOORD_1) and its density; zero elsewhere
    float uvDensity1;
#endif
#ifdef VKRT_HAS_MESH_COLORS
    vec4 color; // the interpolated vertex colour (glTF COLOR_0) multiplying the base colour; white elsewhere
#endif
#ifdef VKRT_TEST_HIT_PROBE
    uint primitive; // HitId::primitive (lib/aov.glsl's hit probe)
#endif
};

// The material a hit sees before its textures: its vertex colour multiplies
// the base (diffuse) colour, as glTF's COLOR_0 does.
Material withVertexColor(Material m, SurfaceHit hit)
{
#ifdef VKRT_HAS_MESH_COLORS
    m.diffuse *= hit.color.rgb;
#endif
    return m;
}

bool hitsLight(SurfaceHit hit) { return hit.shape >= SHAPE_LIGHT; }

// The shading normal on the side of n (the geometric normal facing the ray);
// only meshes with vertex normals have one of their own, and the other
// variants never read the field.
vec3 shadingSide(SurfaceHit hit, vec3 n)
{
#ifdef VKRT_HAS_SHADING_NORMALS
    return hit.front ? hit.shading : -hit.shading;
#else
    return n;
#endif
}

// The closest primitive along the ray: its kind (HIT_Type), index and
// distance, and what the test learnt on the way: a sphere's hit point
// relative to its centre, a box's face normal, a triangle's barycentrics
// (`detail`), and for spheres and boxes whether the ray started outside
// (`front`).
struct HitId {
    int shape;
    uint index;
    float t;
    vec3 detail;
    bool front;
    uint primitive; // a mesh's triangle (its leaf slot); 0 for other kinds
};

HitId noHit(float tMax) { return HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true, 0u); }

// closestType: the nearest of the kind's `count` records before best.t;
// anyHitType: whether any is hit before tMax, stopping at the first.
#define VKRT_RECORD_LOOPS(Type, count)                          \
    void closest##Type(Ray r, TriangleRay tr, inout HitId best) \
    {                                                           \
        for (uint i = 0u; i < (count); ++i) {                   \
            ++g_loopIterations;                                 \
            hitOne##Type(r, tr, i, false, best.t, best);        \
        }                                                       \
    }                                                           \
    bool anyHit##Type(Ray r, TriangleRay tr, float tMax)        \
    {                                                           \
        HitId unused = noHit(tMax);                             \
        for (uint i = 0u; i < (count); ++i) {                   \
            ++g_loopIterations;                                 \
            if (hitOne##Type(r, tr, i, true, tMax, unused))     \
                return true;                                    \
        }                                                       \
        return false;                                           \
    }

#define VKRT_NO_RECORDS(Type)                                       \
    void closest##Type(Ray r, TriangleRay tr, inout HitId best) {} \
    bool anyHit##Type(Ray r, TriangleRay tr, float tMax) { return false; }

// How far off a triangle's plane a point must be for the watertight test
// (lib/intersect.glsl) to tell its side: the test subtracts the ray origin
// from each vertex and shears the result, rounding at the scale of the
// vertices, not of the hit point (gamma(5) of the largest vertex coordinate,
// after pbrt-v4's deltaX/deltaY, section 6.8.4). A ray spawned closer than
// that, leaving at a grazing angle, was measured hitting its own triangle
// (Mesa 26.1, tests/gpu/intersection_probe_test.cpp).
vec3 triangleTestError(vec3 v0, vec3 v1, vec3 v2)
{
    vec3 largest = max(max(abs(v0), abs(v1)), abs(v2));
    return vec3(gammaBound(5) * max(largest.x, max(largest.y, largest.z)));
}

#ifdef VKRT_HAS_TEXTURES
// Texture coordinates of every shape (docs/scene-format.md, "Texture
// coordinates"); the tangent is dp/du's direction, w the sign that makes
// w cross(n, tangent) point along dp/dv.
// Triangles with uvs uv0..uv2 at world edges e1 = v1 - v0, e2 = v2 - v0:
// uv by barycentrics, density from the two areas, the tangent from the uv
// derivatives (Lengyel 2001) when no vertex tangents are given.
// uv area per world area of a triangle (0 when degenerate).
float triangleUvDensity(vec2 uv0, vec2 uv1, vec2 uv2, vec3 e1, vec3 e2)
{
    vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float worldArea = length(cross(e1, e2));
    return worldArea > 0.0 ? abs(d1.x * d2.y - d1.y * d2.x) / worldArea : 0.0;
}

void triangleUv(vec3 bary, vec2 uv0, vec2 uv1, vec2 uv2, vec3 e1, vec3 e2, inout SurfaceHit hit)
{
    hit.uv = bary.x * uv0 + bary.y * uv1 + bary.z * uv2;
    vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float uvCross = d1.x * d2.y - d1.y * d2.x;
    vec3 worldCross = cross(e1, e2);
    float worldArea = length(worldCross);
    hit.uvDensity = worldArea > 0.0 ? abs(uvCross) / worldArea : 0.0;
    vec3 dpdu = (d2.y * e1 - d1.y * e2) * sign(uvCross);
    vec3 dpdv = (d1.x * e2 - d2.x * e1) * sign(uvCross);
    float len = length(dpdu);
    hit.tangent = vec4(len > 0.0 && !isinf(len) ? dpdu / len : normalize(e1),
                       dot(cross(worldCross, dpdu), dpdv) < 0.0 ? -1.0 : 1.0);
}
#endif

#endif
