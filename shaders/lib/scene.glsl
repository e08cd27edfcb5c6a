// The aggregate over every shape and light kind of the registry
// (shared/Kinds.h): traceClosest for the closest hit, traceAny for shadow
// rays. Integrators and light sampling call only these two, so an
// acceleration structure can later replace the per-kind loops behind them.
// Each kind contributes three functions named after its Type:
//   closestType(Ray, inout HitId)        its records' closest hit, if nearer
//   anyHitType(Ray, float tMax) -> bool  whether any record is hit before tMax
//   describeType(Ray, HitId, inout SurfaceHit)  the hit's surface point
// They compile to nothing when the variant lacks the kind. A light kind
// without area (a point) is never hit and has empty functions.
// All loops count into g_loopIterations so the kernel can prove it stayed
// within lavapipe's per-invocation loop budget (shared/Bindings.h).
#ifndef VKRT_SCENE_GLSL
#define VKRT_SCENE_GLSL

uint g_loopIterations = 0u;

// HitId::shape: a SHAPE_* kind (shared/Kinds.h), SHAPE_LIGHT + a LIGHT_* kind
// for a light (black, emitting and opaque), or SHAPE_NONE.
const int SHAPE_NONE = -1;
const int SHAPE_LIGHT = SHAPE_KIND_COUNT;

struct SurfaceHit {
    float t;
    vec3 position;
    vec3 error;  // bound on |position - exact point| per coordinate (offsetRayOrigin)
    vec3 normal; // unit geometric normal; outward for spheres and boxes
    bool front;  // the ray arrived on the side `normal` points to
    uint material;
    int shape;
    uint index;
};

bool hitsLight(SurfaceHit hit) { return hit.shape >= SHAPE_LIGHT; }

// The closest primitive along the ray: its shape kind, index and distance,
// and what the test learnt on the way: a sphere's hit point relative to its
// centre, a box's face normal, a triangle's barycentrics (`detail`), and for
// spheres and boxes whether the ray started outside (`front`).
struct HitId {
    int shape;
    uint index;
    float t;
    vec3 detail;
    bool front;
};

// ------------------------------------------------------------------ spheres

void closestSphere(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_SPHERES
    for (uint i = 0u; i < u.sphereCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 local;
        bool front;
        if (intersectSphere(spheres[i], r, best.t, t, local, front))
            best = HitId(SHAPE_SPHERE, i, t, local, front);
    }
#endif
}

bool anyHitSphere(Ray r, float tMax)
{
#ifdef VKRT_HAS_SPHERES
    for (uint i = 0u; i < u.sphereCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 local;
        bool front;
        if (intersectSphere(spheres[i], r, tMax, t, local, front))
            return true;
    }
#endif
    return false;
}

void describeSphere(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_SPHERES
    // Re-projected onto the sphere (pbrt-v4 section 6.8.5). A sphere far
    // below its centre's float spacing can give local = 0: any normal
    // facing the ray is then as good as another.
    Sphere s = spheres[id.index];
    float len = length(id.detail);
    if (len > 0.0 && !isinf(len))
        hit.normal = id.detail / len;
    else
        hit.normal = id.front ? -r.dir : r.dir;
    vec3 local = s.radius * hit.normal;
    hit.position = s.center + local;
    hit.error = gammaBound(6) * (abs(s.center) + abs(local));
    hit.material = s.material;
#endif
}

// -------------------------------------------------------------------- boxes

void closestBox(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_BOXES
    for (uint i = 0u; i < u.boxCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 n;
        bool front;
        if (intersectBox(boxes[i], r, best.t, t, n, front))
            best = HitId(SHAPE_BOX, i, t, n, front);
    }
#endif
}

bool anyHitBox(Ray r, float tMax)
{
#ifdef VKRT_HAS_BOXES
    for (uint i = 0u; i < u.boxCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 n;
        bool front;
        if (intersectBox(boxes[i], r, tMax, t, n, front))
            return true;
    }
#endif
    return false;
}

void describeBox(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_BOXES
    // The coordinate across the face is the face's own, exactly.
    Box b = boxes[id.index];
    hit.normal = id.detail;
    int axis = id.detail.x != 0.0 ? 0 : (id.detail.y != 0.0 ? 1 : 2);
    hit.position[axis] = id.detail[axis] > 0.0 ? b.upper[axis] : b.lower[axis];
    hit.error[axis] = 0.0;
    hit.material = b.material;
#endif
}

// ---------------------------------------------------------------- triangles

void closestTriangle(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLES
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 bary;
        Triangle tri = triangles[i];
        if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, best.t, t, bary))
            best = HitId(SHAPE_TRIANGLE, i, t, bary, true);
    }
#endif
}

bool anyHitTriangle(Ray r, float tMax)
{
#ifdef VKRT_HAS_TRIANGLES
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 bary;
        Triangle tri = triangles[i];
        if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, tMax, t, bary))
            return true;
    }
#endif
    return false;
}

void describeTriangle(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_TRIANGLES
    // Barycentric interpolation: error gamma(7) sum |b_i v_i| (pbrt-v4 6.8.5).
    Triangle tri = triangles[id.index];
    hit.normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
    vec3 b0 = id.detail.x * tri.v0, b1 = id.detail.y * tri.v1, b2 = id.detail.z * tri.v2;
    hit.position = b0 + b1 + b2;
    hit.error = gammaBound(7) * (abs(b0) + abs(b1) + abs(b2));
    hit.front = dot(hit.normal, r.dir) < 0.0;
    hit.material = tri.material;
#endif
}

// ------------------------------------------------------------------- planes

void closestPlane(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_PLANES
    for (uint i = 0u; i < u.planeCount; ++i) {
        ++g_loopIterations;
        float t;
        if (intersectPlane(planes[i], r, best.t, t))
            best = HitId(SHAPE_PLANE, i, t, vec3(0.0), true);
    }
#endif
}

bool anyHitPlane(Ray r, float tMax)
{
#ifdef VKRT_HAS_PLANES
    for (uint i = 0u; i < u.planeCount; ++i) {
        ++g_loopIterations;
        float t;
        if (intersectPlane(planes[i], r, tMax, t))
            return true;
    }
#endif
    return false;
}

void describePlane(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_PLANES
    // Projected onto the plane; what remains is the rounding of that step.
    Plane p = planes[id.index];
    hit.normal = p.normal;
    hit.position -= dot(hit.position - p.point, p.normal) * p.normal;
    hit.error = gammaBound(6) * (abs(hit.position) + abs(p.point));
    hit.front = dot(hit.normal, r.dir) < 0.0;
    hit.material = p.material;
#endif
}

// ------------------------------------------------------------- point lights

void closestPointLight(Ray r, inout HitId best) {}
bool anyHitPointLight(Ray r, float tMax) { return false; }
void describePointLight(Ray r, HitId id, inout SurfaceHit hit) {}

// ---------------------------------------------------------- triangle lights

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
// Unit normal of a triangle light: the side its counter-clockwise winding faces.
vec3 triangleLightNormal(TriangleLight light) { return normalize(cross(light.v1 - light.v0, light.v2 - light.v0)); }
#endif

void closestTriangleLight(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 bary;
        TriangleLight light = triangleLights[i];
        if (intersectTriangle(light.v0, light.v1, light.v2, r, tr, best.t, t, bary))
            best = HitId(SHAPE_LIGHT + LIGHT_TRIANGLE, i, t, bary, true);
    }
#endif
}

bool anyHitTriangleLight(Ray r, float tMax)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 bary;
        TriangleLight light = triangleLights[i];
        if (intersectTriangle(light.v0, light.v1, light.v2, r, tr, tMax, t, bary))
            return true;
    }
#endif
    return false;
}

void describeTriangleLight(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    hit.normal = triangleLightNormal(triangleLights[id.index]);
    hit.front = dot(hit.normal, r.dir) < 0.0;
#endif
}

// --------------------------------------------------------------- aggregate

#define VKRT_CLOSEST_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity) closest##Type(r, best);
#define VKRT_ANY_HIT_OF_KIND(KIND, Type, name, value, field, array, ARRAY, capacity) \
    if (anyHit##Type(r, tMax))                                                      \
        return true;
#define VKRT_DESCRIBE_SHAPE(KIND, Type, name, value, field, array, ARRAY, capacity) \
    if (id.shape == SHAPE_##KIND)                                                   \
        describe##Type(r, id, hit);
#define VKRT_DESCRIBE_LIGHT(KIND, Type, name, value, field, array, ARRAY, capacity) \
    if (id.shape == SHAPE_LIGHT + LIGHT_##KIND)                                     \
        describe##Type(r, id, hit);

// The closest hit over every kind, shapes first, in registry order.
HitId findClosest(Ray r, float tMax)
{
    HitId best = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true);
    VKRT_SHAPE_KINDS(VKRT_CLOSEST_OF_KIND)
    VKRT_LIGHT_KINDS(VKRT_CLOSEST_OF_KIND)
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
    hit.shape = id.shape;
    hit.index = id.index;
    hit.material = 0u;
    VKRT_SHAPE_KINDS(VKRT_DESCRIBE_SHAPE)
    VKRT_LIGHT_KINDS(VKRT_DESCRIBE_LIGHT)
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
    VKRT_SHAPE_KINDS(VKRT_ANY_HIT_OF_KIND)
    VKRT_LIGHT_KINDS(VKRT_ANY_HIT_OF_KIND)
    return false;
}

#endif
