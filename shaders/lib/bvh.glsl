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

#endif
