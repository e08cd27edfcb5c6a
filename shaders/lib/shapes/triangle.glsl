// Single triangles (`shape = "triangle"`): the records, the watertight test
// (lib/intersect.glsl: intersectTriangle), barycentric interpolation.
#ifndef VKRT_SHAPE_TRIANGLE_GLSL
#define VKRT_SHAPE_TRIANGLE_GLSL

#ifdef VKRT_HAS_TRIANGLES
VKRT_SCENE_ARRAY(BINDING_TRIANGLES, TriangleBlock, Triangle, triangles, UNIFORM_TRIANGLES)
#define triangles VKRT_SCENE_ITEMS(BINDING_TRIANGLES, TriangleBlock, triangles)
#endif

bool hitOneTriangle(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#ifdef VKRT_HAS_TRIANGLES
    float t;
    vec3 bary;
    Triangle tri = triangles[i];
    if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, tMax, t, bary)) {
        hit = HitId(HIT_Triangle, i, t, bary, true, 0u);
        return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_TRIANGLES
VKRT_RECORD_LOOPS(Triangle, u.triangleCount)
#else
VKRT_NO_RECORDS(Triangle)
#endif

void describeTriangle(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_TRIANGLES
    // Barycentric interpolation: error gamma(7) sum |b_i v_i| (pbrt-v4 6.8.5).
    // precise: no fused multiply-adds (lib/intersect.glsl says why).
    Triangle tri = triangles[id.index];
    precise vec3 area = cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
    hit.normal = normalize(area);
    precise vec3 b0 = id.detail.x * tri.v0, b1 = id.detail.y * tri.v1, b2 = id.detail.z * tri.v2;
    precise vec3 position = b0 + b1 + b2;
    hit.position = position;
    hit.error = gammaBound(7) * (abs(b0) + abs(b1) + abs(b2)) + triangleTestError(tri.v0, tri.v1, tri.v2);
    hit.front = dot(hit.normal, r.dir) < 0.0;
    hit.material = tri.material;
#ifdef VKRT_HAS_TEXTURES
    triangleUv(id.detail, vec2(0.0), vec2(1.0, 0.0), vec2(0.0, 1.0), tri.v1 - tri.v0, tri.v2 - tri.v0, hit);
#endif
#endif
}

#endif
