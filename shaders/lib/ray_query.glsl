// The driver traversal backend (`--accel driver`, VKRT_ACCEL_DRIVER): the
// device's own acceleration structures, walked with VK_KHR_ray_query, answer
// findHit (lib/scene.glsl) for every bounded record.
// render/DriverAccel.cpp builds them:
//   - one bottom-level structure of opaque triangles per mesh geometry, its
//     triangles in meshTriangles' order (so the driver's primitive index is
//     the own backend's leaf slot), one instance per mesh record (custom
//     index = the record) with the record's camera-relative toWorld;
//   - per other bounded kind of the registry (spheres, boxes, triangles,
//     triangle lights), one structure of boxes, one per record, intersected
//     here by the kind's own test (hitOneType), so hit points, their error
//     bounds and the self-intersection rules are the own backend's.
// Every instance's shader-binding-table offset is its kind's HIT_Type code.
// Unbounded kinds (planes) stay the loops of lib/scene.glsl.
#ifndef VKRT_RAY_QUERY_GLSL
#define VKRT_RAY_QUERY_GLSL

layout(binding = BINDING_TOP_LEVEL) uniform accelerationStructureEXT topLevel;

#define VKRT_HIT_RECORD_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if (bounded != 0 && kind == HIT_##Type)                                                     \
        return hitOne##Type(r, tr, i, anyHit, tMax, hit);

// Record i of kind `kind` (a box candidate), by the kind's own test.
bool hitRecordOfKind(int kind, uint i, Ray r, TriangleRay tr, bool anyHit, float tMax, inout HitId hit)
{
    VKRT_SHAPE_KINDS(VKRT_HIT_RECORD_OF_KIND)
    VKRT_LIGHT_KINDS(VKRT_HIT_RECORD_OF_KIND)
    return false;
}

#ifdef VKRT_HAS_ALPHA
// Whether the alpha test (lib/alpha.glsl) keeps the query's candidate
// triangle `slot` of mesh instance `instance`, with the same coin as the own
// backend's walk (the world ray, the instance, the triangle's leaf slot);
// b: Vulkan's barycentrics (weights of v1 and v2).
bool driverAlphaKeeps(Ray r, int instance, int slot, vec2 b)
{
    return alphaKeeps(r, uint(instance), meshes[uint(instance)], uint(slot), vec3(1.0 - b.x - b.y, b.x, b.y));
}
#endif

// The closest bounded record before tMax (written to best), or (anyHit)
// whether any lies before tMax. Candidates' boxes are tested by their kind
// against the distance committed so far, and a hit is committed with its own
// distance; the driver commits mesh triangles itself.
bool traceDriver(Ray r, TriangleRay tr, bool anyHit, float tMax, inout HitId best)
{
    rayQueryEXT query;
    // Triangles count from both sides (the own test is two-sided too);
    // a shadow ray stops at the first opaque hit.
    uint flags = anyHit ? gl_RayFlagsTerminateOnFirstHitEXT : gl_RayFlagsNoneEXT;
    rayQueryInitializeEXT(query, topLevel, flags, 0xffu, r.origin, 0.0, r.dir, tMax);
    HitId generated = best;
    while (rayQueryProceedEXT(query)) {
        ++g_loopIterations;
#ifdef VKRT_HAS_ALPHA
        // A triangle of an alpha-tested instance (not opaque: DriverAccel.cpp)
        // counts only where its alpha test keeps it.
        // A candidate beyond the committed hit is left alone.
        if (rayQueryGetIntersectionTypeEXT(query, false) == gl_RayQueryCandidateIntersectionTriangleEXT) {
            bool before = rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionNoneEXT ||
                          rayQueryGetIntersectionTEXT(query, false) < rayQueryGetIntersectionTEXT(query, true);
            if (before && driverAlphaKeeps(r, rayQueryGetIntersectionInstanceCustomIndexEXT(query, false),
                                           rayQueryGetIntersectionPrimitiveIndexEXT(query, false),
                                           rayQueryGetIntersectionBarycentricsEXT(query, false)))
                rayQueryConfirmIntersectionEXT(query);
            continue;
        }
#endif
        if (rayQueryGetIntersectionTypeEXT(query, false) != gl_RayQueryCandidateIntersectionAABBEXT)
            continue;
        int kind = int(rayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetEXT(query, false));
        uint i = uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, false));
        bool committedSoFar =
            rayQueryGetIntersectionTypeEXT(query, true) != gl_RayQueryCommittedIntersectionNoneEXT;
        float limit = committedSoFar ? rayQueryGetIntersectionTEXT(query, true) : tMax;
        HitId candidate = noHit(limit);
        if (!hitRecordOfKind(kind, i, r, tr, anyHit, limit, candidate))
            continue;
        if (anyHit) {
            rayQueryTerminateEXT(query);
            return true;
        }
        generated = candidate;
        rayQueryGenerateIntersectionEXT(query, candidate.t);
    }
    uint committed = rayQueryGetIntersectionTypeEXT(query, true);
    if (committed == gl_RayQueryCommittedIntersectionTriangleEXT) {
        if (anyHit)
            return true;
        // Vulkan's barycentrics weigh v1 and v2; HitId's weigh v0, v1, v2.
        vec2 b = rayQueryGetIntersectionBarycentricsEXT(query, true);
        best = HitId(SHAPE_MESH, uint(rayQueryGetIntersectionInstanceCustomIndexEXT(query, true)),
                     rayQueryGetIntersectionTEXT(query, true), vec3(1.0 - b.x - b.y, b.x, b.y), true,
                     uint(rayQueryGetIntersectionPrimitiveIndexEXT(query, true)));
        return true;
    }
    if (committed == gl_RayQueryCommittedIntersectionGeneratedEXT) {
        best = generated;
        return true;
    }
    return false;
}

#endif
