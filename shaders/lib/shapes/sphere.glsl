// Spheres (`shape = "sphere"`): the records, their test (lib/intersect.glsl:
// intersectSphere), the hit point re-projected onto the sphere, and uvs.
#ifndef VKRT_SHAPE_SPHERE_GLSL
#define VKRT_SHAPE_SPHERE_GLSL

#ifdef VKRT_HAS_SPHERES
VKRT_SCENE_ARRAY(BINDING_SPHERES, SphereBlock, Sphere, spheres, UNIFORM_SPHERES)
#define spheres VKRT_SCENE_ITEMS(BINDING_SPHERES, SphereBlock, spheres)
#endif

bool hitOneSphere(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#ifdef VKRT_HAS_SPHERES
    float t;
    vec3 local;
    bool front;
    if (intersectSphere(spheres[i], r, tMax, t, local, front)) {
        hit = HitId(HIT_Sphere, i, t, local, front, 0u);
        return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_SPHERES
VKRT_RECORD_LOOPS(Sphere, u.sphereCount)
#else
VKRT_NO_RECORDS(Sphere)
#endif

#ifdef VKRT_HAS_TEXTURES
// Longitude and latitude about the world y axis, u = 0.5 at +z and growing
// towards +x, v from 0 at the bottom pole to 1 at the top.
// du dv / dA = 1 / (2 pi^2 r^2 cos(latitude)).
void sphereUv(vec3 n, float radius, inout SurfaceHit hit)
{
    float cosLatitude = sqrt(max(1.0 - n.y * n.y, 0.0));
    hit.uv = vec2(0.5 + atan(n.x, n.z) * (0.5 * INV_PI), 0.5 + asin(clamp(n.y, -1.0, 1.0)) * INV_PI);
    hit.uvDensity = 1.0 / (2.0 * PI * PI * radius * radius * max(cosLatitude, 1e-3));
    vec3 east = vec3(n.z, 0.0, -n.x);
    hit.tangent = vec4(cosLatitude > 1e-6 ? east / cosLatitude : vec3(1.0, 0.0, 0.0), 1.0);
}
#endif

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
#ifdef VKRT_HAS_TEXTURES
    sphereUv(hit.normal, s.radius, hit);
#endif
#endif
}

#endif
