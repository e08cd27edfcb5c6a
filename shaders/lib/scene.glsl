// The aggregate over every shape and light kind of the registry
// (shared/Kinds.h): traceClosest for the closest hit, traceAny for shadow
// rays, and findHit behind both (the path integrator calls it for both kinds
// of ray from one site). Integrators and light sampling call only these, so
// an acceleration structure can replace the per-kind loops behind them.
// Each kind's file supplies the functions lib/surface.glsl lists; everything
// here is expanded from the registry, so a kind is added there, in its own
// files and in the includes below (a light kind's file is included again by
// lib/lights.glsl for its sampling).
#ifndef VKRT_SCENE_GLSL
#define VKRT_SCENE_GLSL

#include "surface.glsl"
#include "shapes/sphere.glsl"
#include "shapes/box.glsl"
#include "shapes/triangle.glsl"
#include "shapes/plane.glsl"
#include "shapes/mesh.glsl"
#include "lights/point.glsl"
#include "lights/triangle.glsl"
#include "lights/directional.glsl"
#include "lights/spot.glsl"
#ifdef VKRT_ACCEL_DRIVER
#include "ray_query.glsl"
#endif

#define VKRT_CLOSEST_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    closest##Type(r, tr, best);
#define VKRT_ANY_HIT_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (anyHit##Type(r, tr, tMax))                                                           \
        return true;
#define VKRT_CLOSEST_IF_UNBOUNDED(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (bounded == 0)                                                                              \
        closest##Type(r, tr, best);
#define VKRT_ANY_HIT_IF_UNBOUNDED(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (bounded == 0 && anyHit##Type(r, tr, tMax))                                                 \
        return true;
#define VKRT_DESCRIBE_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (id.shape == HIT_##Type)                                                             \
        describe##Type(r, id, hit);

#if defined(VKRT_HAS_MESHES) && !defined(VKRT_ACCEL_DRIVER)
VKRT_READ_BUFFER(BINDING_TOP_NODES, TopNodeBlock, BvhNode, topNodes)
#define topNodes VKRT_READ_ITEMS(BINDING_TOP_NODES, TopNodeBlock, topNodes)
VKRT_READ_BUFFER(BINDING_TOP_REFS, TopRefBlock, uint, topRefs)
#define topRefs VKRT_READ_ITEMS(BINDING_TOP_REFS, TopRefBlock, topRefs)

// One record of the top-level BVH, TOP_REF(HIT_Type, index) (shared/SceneTypes.h):
// every kind of the registry with bounded = 1, as the host builds it
// (src/render/GpuScene.cpp: buildTopLevel).
#define VKRT_HIT_RECORD(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (bounded != 0 && kind == HIT_##Type)                                             \
        return hitOne##Type(r, tr, i, anyHit, tMax, best);

// Whether the ray hits record `ref` before tMax; without anyHit, best
// becomes that hit. One call per kind for both kinds of ray: lavapipe
// inlines each, and a mesh's is its whole BVH walk.
bool hitRecord(Ray r, TriangleRay tr, uint ref, bool anyHit, float tMax, inout HitId best)
{
    int kind = int(ref >> TOP_REF_INDEX_BITS);
    uint i = ref & TOP_REF_MAX_INDEX;
    VKRT_SHAPE_KINDS(VKRT_HIT_RECORD)
    VKRT_LIGHT_KINDS(VKRT_HIT_RECORD)
    return false;
}

// The top-level BVH over every bounded record (the unbounded kinds stay a
// loop): the closest hit, or (anyHit) whether anything lies before tMax.
bool traverseTop(Ray r, TriangleRay tr, bool anyHit, float tMax, inout HitId best)
{
    BvhRay br = bvhRaySetup(r);
    VKRT_BVH_WALK_STATE
    BvhNode root = topNodes[0];
    bool visiting = entersBox(root.lower, root.upper, br, anyHit ? tMax : best.t, tEntry);
    while (visiting) {
        ++g_loopIterations;
        BvhNode n = topNodes[node];
        bool descend = false;
        if (n.count > 0u) {
            for (uint k = 0u; k < n.count; ++k) {
                ++g_loopIterations;
                uint ref = topRefs[n.first + k];
                if (hitRecord(r, tr, ref, anyHit, anyHit ? tMax : best.t, best) && anyHit)
                    return true;
            }
        } else {
            float limit = anyHit ? tMax : best.t;
            BvhNode a = topNodes[n.first];
            BvhNode b = topNodes[n.first + 1u];
            VKRT_BVH_DESCEND(a, b, n.first, br, limit, descend)
        }
        VKRT_BVH_POP_UNLESS(descend, anyHit ? tMax : best.t)
    }
    return false;
}
#endif

// Whether the ray meets anything (surface or light) before tMax: without
// anyHit, best is then the closest hit over every kind (shapes first, in
// registry order); with anyHit the walk stops at the first record found and
// best says nothing. One function for both kinds of ray, so that the path
// integrator, which traces both from one call site with vkrt's own BVH
// (lib/path.glsl: advancePath), gets one copy of the walk where the driver
// inlines every call (docs/performance.md, round four). With meshes, the top-level
// BVH replaces the loops over the bounded kinds.
bool findHit(Ray r, float tMax, bool anyHit, out HitId best)
{
    best = noHit(tMax);
    TriangleRay tr = triangleRaySetup(r);
#if defined(VKRT_ACCEL_DRIVER) || defined(VKRT_HAS_MESHES)
#ifndef VKRT_ACCEL_DRIVER
    if (u.topNodeCount > 0u)
#endif
    {
        if (anyHit) {
            VKRT_SHAPE_KINDS(VKRT_ANY_HIT_IF_UNBOUNDED)
            VKRT_LIGHT_KINDS(VKRT_ANY_HIT_IF_UNBOUNDED)
        } else {
            VKRT_SHAPE_KINDS(VKRT_CLOSEST_IF_UNBOUNDED)
            VKRT_LIGHT_KINDS(VKRT_CLOSEST_IF_UNBOUNDED)
        }
#ifdef VKRT_ACCEL_DRIVER
        return traceDriver(r, tr, anyHit, best.t, best) || best.shape != SHAPE_NONE;
#else
        return traverseTop(r, tr, anyHit, best.t, best) || best.shape != SHAPE_NONE;
#endif
    }
#endif
    if (anyHit) {
        VKRT_SHAPE_KINDS(VKRT_ANY_HIT_OF_KIND)
        VKRT_LIGHT_KINDS(VKRT_ANY_HIT_OF_KIND)
        return false;
    }
    VKRT_SHAPE_KINDS(VKRT_CLOSEST_OF_KIND)
    VKRT_LIGHT_KINDS(VKRT_CLOSEST_OF_KIND)
    return best.shape != SHAPE_NONE;
}

// The closest hit before tMax (shape SHAPE_NONE if there is none).
HitId findClosest(Ray r, float tMax)
{
    HitId best;
    findHit(r, tMax, false, best);
    return best;
}

// Position (with its error bound), normal, side and material of the hit.
// Each kind recomputes the point from what its test learnt, far more
// accurately than origin + t * dir, whose error grows with |origin| and t.
SurfaceHit describeHit(Ray r, HitId id)
{
    SurfaceHit hit;
    hit.t = id.t;
    hit.position = r.origin + id.t * r.dir;
    hit.error = gammaBound(3) * (abs(r.origin) + abs(id.t * r.dir));
    hit.normal = -r.dir;
    hit.front = id.front;
#if defined(VKRT_HAS_MESHES) || defined(VKRT_HAS_EMITTERS)
    hit.emitter = NO_EMITTER;
#endif
    hit.shape = id.shape;
    hit.index = id.index;
#ifdef VKRT_TEST_HIT_PROBE
    hit.primitive = id.primitive;
#endif
    hit.material = 0u;
#ifdef VKRT_HAS_TEXTURES
    hit.uv = vec2(0.0);
    hit.uvDensity = 0.0;
    hit.tangent = vec4(1.0, 0.0, 0.0, 1.0);
#endif
#ifdef VKRT_HAS_MESH_UVS1
    hit.uv1 = vec2(0.0);
    hit.uvDensity1 = 0.0;
#endif
#ifdef VKRT_HAS_MESH_COLORS
    hit.color = vec4(1.0);
#endif
    VKRT_SHAPE_KINDS(VKRT_DESCRIBE_KIND)
    VKRT_LIGHT_KINDS(VKRT_DESCRIBE_KIND)
    // Meshes set their own shading normal; normal maps may change it later.
#ifdef VKRT_HAS_MESHES
    if (id.shape != HIT_Mesh)
#endif
        hit.shading = hit.normal;
    return hit;
}

// The closest surface or light along the ray before tMax.
bool traceClosest(Ray r, float tMax, out SurfaceHit hit)
{
    HitId id = findClosest(r, tMax);
    if (id.shape == SHAPE_NONE)
        return false;
    hit = describeHit(r, id);
    return true;
}

// Whether anything (surface or light) lies along the ray before tMax; stops
// at the first record found. For shadow rays to which every surface is
// opaque; the Whitted integrator's shadow rays through glass walk the
// interfaces in order with traceClosest instead (lib/lights.glsl).
bool traceAny(Ray r, float tMax)
{
    HitId unused;
    return findHit(r, tMax, true, unused);
}

#endif
