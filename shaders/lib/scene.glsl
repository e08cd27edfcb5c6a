// Closest-hit and shadow queries over every primitive buffer of the variant.
// All loops count into g_loopIterations so the kernel can prove it stayed
// within lavapipe's per-invocation loop budget (shared/Bindings.h).
#ifndef VKRT_SCENE_GLSL
#define VKRT_SCENE_GLSL

uint g_loopIterations = 0u;

const int SHAPE_NONE = -1;
const int SHAPE_SPHERE = 0;
const int SHAPE_BOX = 1;
const int SHAPE_TRIANGLE = 2;
const int SHAPE_PLANE = 3;
const int SHAPE_LIGHT = 4; // a triangle light: black, emitting, and opaque

struct SurfaceHit {
    float t;
    vec3 position;
    vec3 normal; // unit geometric normal; outward for spheres and boxes
    uint material;
    int shape;
    uint index;
};

// The closest primitive along the ray: its shape kind, index and distance.
struct HitId {
    int shape;
    uint index;
    float t;
    vec3 boxNormal; // boxes report their face normal during the test
};

void closestSpheres(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_SPHERES
    for (uint i = 0u; i < u.sphereCount; ++i) {
        ++g_loopIterations;
        float t;
        if (intersectSphere(spheres[i], r, best.t, t))
            best = HitId(SHAPE_SPHERE, i, t, vec3(0.0));
    }
#endif
}

void closestBoxes(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_BOXES
    for (uint i = 0u; i < u.boxCount; ++i) {
        ++g_loopIterations;
        float t;
        vec3 n;
        if (intersectBox(boxes[i], r, best.t, t, n))
            best = HitId(SHAPE_BOX, i, t, n);
    }
#endif
}

void closestTriangles(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLES
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleCount; ++i) {
        ++g_loopIterations;
        float t;
        Triangle tri = triangles[i];
        if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, best.t, t))
            best = HitId(SHAPE_TRIANGLE, i, t, vec3(0.0));
    }
#endif
}

void closestPlanes(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_PLANES
    for (uint i = 0u; i < u.planeCount; ++i) {
        ++g_loopIterations;
        float t;
        if (intersectPlane(planes[i], r, best.t, t))
            best = HitId(SHAPE_PLANE, i, t, vec3(0.0));
    }
#endif
}

void closestLights(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        float t;
        TriangleLight light = triangleLights[i];
        if (intersectTriangle(light.v0, light.v1, light.v2, r, tr, best.t, t))
            best = HitId(SHAPE_LIGHT, i, t, vec3(0.0));
    }
#endif
}

HitId findClosest(Ray r, float tMax)
{
    HitId best = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0));
    closestSpheres(r, best);
    closestBoxes(r, best);
    closestTriangles(r, best);
    closestPlanes(r, best);
    closestLights(r, best);
    return best;
}

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
// Unit normal of a triangle light: the side its counter-clockwise winding faces.
vec3 triangleLightNormal(TriangleLight light) { return normalize(cross(light.v1 - light.v0, light.v2 - light.v0)); }
#endif

// Position, normal and material of the hit. Spheres and planes re-project the
// point onto the surface, which removes the error of origin + t * dir.
SurfaceHit describeHit(Ray r, HitId id)
{
    SurfaceHit hit;
    hit.t = id.t;
    hit.position = r.origin + id.t * r.dir;
    hit.shape = id.shape;
    hit.index = id.index;
    hit.material = 0u;
#ifdef VKRT_HAS_SPHERES
    if (id.shape == SHAPE_SPHERE) {
        Sphere s = spheres[id.index];
        hit.normal = normalize(hit.position - s.center);
        hit.position = s.center + s.radius * hit.normal;
        hit.material = s.material;
    }
#endif
#ifdef VKRT_HAS_BOXES
    if (id.shape == SHAPE_BOX) {
        hit.normal = id.boxNormal;
        hit.material = boxes[id.index].material;
    }
#endif
#ifdef VKRT_HAS_TRIANGLES
    if (id.shape == SHAPE_TRIANGLE) {
        Triangle tri = triangles[id.index];
        hit.normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
        hit.material = tri.material;
    }
#endif
#ifdef VKRT_HAS_PLANES
    if (id.shape == SHAPE_PLANE) {
        Plane p = planes[id.index];
        hit.normal = p.normal;
        hit.position -= dot(hit.position - p.point, p.normal) * p.normal;
        hit.material = p.material;
    }
#endif
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    if (id.shape == SHAPE_LIGHT)
        hit.normal = triangleLightNormal(triangleLights[id.index]);
#endif
    return hit;
}

bool traceClosest(Ray r, float tMax, out SurfaceHit hit)
{
    HitId id = findClosest(r, tMax);
    if (id.shape == SHAPE_NONE)
        return false;
    hit = describeHit(r, id);
    return true;
}


#endif
