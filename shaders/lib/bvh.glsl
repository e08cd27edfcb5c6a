// Ray-box tests for BVH traversal (the trees of src/accel/Bvh.h). Node
// boxes are rounded outwards on the host, and the far distance of every slab
// test is widened by 2 gamma(3) (pbrt-v4 section 6.8.2), so a ray that
// touches a primitive never misses the boxes around it through rounding.
#ifndef VKRT_BVH_GLSL
#define VKRT_BVH_GLSL

struct BvhRay {
    vec3 origin;
    vec3 invDir;
};

// A zero direction component becomes a tiny one of the same sign: 1 / 0
// would give inf, and 0 * inf = NaN for an origin on a slab's plane.
BvhRay bvhRaySetup(Ray r)
{
    vec3 d = r.dir;
    const float tiny = 1e-30;
    d.x = d.x == 0.0 ? tiny : d.x;
    d.y = d.y == 0.0 ? tiny : d.y;
    d.z = d.z == 0.0 ? tiny : d.z;
    return BvhRay(r.origin, 1.0 / d);
}

// Whether the ray enters the box before tMax, and where (0 when it starts inside).
bool entersBox(vec3 lower, vec3 upper, BvhRay r, float tMax, out float tEntry)
{
    vec3 t0 = (lower - r.origin) * r.invDir;
    vec3 t1 = (upper - r.origin) * r.invDir;
    vec3 tNear = min(t0, t1);
    vec3 tFar = max(t0, t1);
    tEntry = max(max(tNear.x, tNear.y), max(tNear.z, 0.0));
    float tExit = min(min(tFar.x, tFar.y), min(tFar.z, tMax)) * (1.0 + 2.0 * gammaBound(3));
    return tEntry <= tExit;
}

// The stack walk of both trees, the top level (lib/scene.glsl: traverseTop)
// and each mesh's (lib/shapes/mesh.glsl: traverseMesh), written once: a
// walker declares VKRT_BVH_WALK_STATE, and for each node it visits either
// handles a leaf or calls VKRT_BVH_DESCEND on its two children, then
// VKRT_BVH_POP_UNLESS(descend, limit) takes the next node from the stack
// (near child first; nodes entered beyond `limit` are skipped).
#define VKRT_BVH_WALK_STATE                \
    uint stackNode[BVH_STACK_SIZE];        \
    float stackEntry[BVH_STACK_SIZE];      \
    uint depth = 0u;                       \
    uint node = 0u;                        \
    float tEntry;

#define VKRT_BVH_DESCEND(a, b, first, br, limit, descend)           \
    {                                                              \
        float ta, tb;                                              \
        bool ha = entersBox(a.lower, a.upper, br, limit, ta);      \
        bool hb = entersBox(b.lower, b.upper, br, limit, tb);      \
        if (ha && hb) {                                            \
            bool aFirst = ta <= tb;                                \
            stackNode[depth] = aFirst ? first + 1u : first;        \
            stackEntry[depth] = aFirst ? tb : ta;                  \
            ++depth;                                               \
            node = aFirst ? first : first + 1u;                    \
            descend = true;                                        \
        } else if (ha || hb) {                                     \
            node = ha ? first : first + 1u;                        \
            descend = true;                                        \
        }                                                          \
    }

#define VKRT_BVH_POP_UNLESS(descend, limit)             \
    if (!descend) {                                     \
        visiting = false;                               \
        while (depth > 0u) {                            \
            ++g_loopIterations;                         \
            --depth;                                    \
            if (stackEntry[depth] <= (limit)) {         \
                node = stackNode[depth];                \
                visiting = true;                        \
                break;                                  \
            }                                           \
        }                                               \
    }

#endif
