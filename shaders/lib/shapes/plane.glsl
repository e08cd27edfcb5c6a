// Infinite planes (`shape = "plane"`): unbounded, so never in the top-level
// BVH (registry column `bounded` = 0): a loop in every variant.
#ifndef VKRT_SHAPE_PLANE_GLSL
#define VKRT_SHAPE_PLANE_GLSL

#ifdef VKRT_HAS_PLANES
VKRT_SCENE_ARRAY(BINDING_PLANES, PlaneBlock, Plane, planes, UNIFORM_PLANES)
#define planes VKRT_SCENE_ITEMS(BINDING_PLANES, PlaneBlock, planes)
#endif

bool hitOnePlane(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#ifdef VKRT_HAS_PLANES
    float t;
    if (intersectPlane(planes[i], r, tMax, t)) {
        hit = HitId(HIT_Plane, i, t, vec3(0.0), true, 0u);
        return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_PLANES
VKRT_RECORD_LOOPS(Plane, u.planeCount)
#else
VKRT_NO_RECORDS(Plane)
#endif

#ifdef VKRT_HAS_TEXTURES
// World distances from the plane's point along two axes in it, one uv unit
// per scene unit: tangent = normalize(cross(+y, n)) (+x for horizontal
// planes), bitangent = cross(n, tangent).
void planeUv(Plane pl, vec3 p, inout SurfaceHit hit)
{
    vec3 side = cross(vec3(0.0, 1.0, 0.0), pl.normal);
    float len = length(side);
    vec3 t = len > 1e-6 ? side / len : vec3(1.0, 0.0, 0.0);
    vec3 b = cross(pl.normal, t);
    vec3 d = p - pl.point;
    hit.uv = vec2(dot(d, t), dot(d, b));
    hit.uvDensity = 1.0;
    hit.tangent = vec4(t, 1.0);
}
#endif

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
#ifdef VKRT_HAS_TEXTURES
    planeUv(p, hit.position, hit);
#endif
#endif
}

#endif
