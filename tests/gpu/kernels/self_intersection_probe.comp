// Secondary rays spawned on a surface exactly as the renderer spawns them.
// The scene is one primitive, held in private arrays that stand in for the
// render kernel's storage buffers so that lib/scene.glsl's findClosest and
// describeHit run unchanged. inputs[21i ..] = kind (0 sphere, 1 box,
// 2 triangle, 3 plane), 9 shape parameters (as in intersect_probe.comp),
// primary ray origin, the point it is aimed at, a local direction (z > 0) in
// the frame of the side the new ray leaves into, mode (0: bounce to the side
// the primary ray came from, 1: transmission to the other side, 2: shadow ray
// towards a point light at hit + distance * direction, as
// directFromPointLight does), light distance.
// outputs[15i ..] = primary hit flag, second hit flag, second t, new ray
// origin, new ray direction, dot(direction, side normal), surface point,
// front-face flag, traceAny's answer for the second ray (it must agree
// with the second hit flag of the closest-hit query).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/intersect.glsl"
#include "lib/sampling.glsl"

#define VKRT_HAS_SPHERES 1
#define VKRT_HAS_BOXES 1
#define VKRT_HAS_TRIANGLES 1
#define VKRT_HAS_PLANES 1
SceneUniforms u;
Sphere spheres[1];
Box boxes[1];
Triangle triangles[1];
Plane planes[1];
// The probe's records are the globals above: the kinds' buffer declarations are left out.
#define VKRT_SCENE_ARRAY(binding_, Block, Type, name, capacity)
#define VKRT_SCENE_ITEMS(binding_, Block, name) name
#include "lib/scene.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint base = 21u * i;
    int kind = int(inputs[base]);
    vec3 p0 = vec3(inputs[base + 1u], inputs[base + 2u], inputs[base + 3u]);
    vec3 p1 = vec3(inputs[base + 4u], inputs[base + 5u], inputs[base + 6u]);
    vec3 p2 = vec3(inputs[base + 7u], inputs[base + 8u], inputs[base + 9u]);
    vec3 primaryOrigin = vec3(inputs[base + 10u], inputs[base + 11u], inputs[base + 12u]);
    vec3 aim = vec3(inputs[base + 13u], inputs[base + 14u], inputs[base + 15u]);
    vec3 local = vec3(inputs[base + 16u], inputs[base + 17u], inputs[base + 18u]);
    int mode = int(inputs[base + 19u]);
    float lightDistance = inputs[base + 20u];

    u.sphereCount = kind == 0 ? 1u : 0u;
    u.boxCount = kind == 1 ? 1u : 0u;
    u.triangleCount = kind == 2 ? 1u : 0u;
    u.planeCount = kind == 3 ? 1u : 0u;
    spheres[0] = Sphere(p0, p1.x, 0u);
    boxes[0] = Box(p0, 0u, p1);
    triangles[0] = Triangle(p0, 0u, p1, p2);
    planes[0] = Plane(p0, 0u, p1);

    uint o = 15u * i;
    for (uint k = 0u; k < 15u; ++k)
        outputs[o + k] = 0.0;
    Ray primary = Ray(primaryOrigin, normalize(aim - primaryOrigin));
    SurfaceHit hit;
    if (!traceClosest(primary, FLT_MAX, hit))
        return;
    // As the integrators do: n faces the side the primary ray came from.
    bool frontFace = hit.front;
    vec3 n = frontFace ? hit.normal : -hit.normal;
    vec3 side = mode == 1 ? -n : n;
    vec3 dir = normalize(fromLocal(local, side));
    vec3 origin = offsetRayOrigin(hit.position, hit.error, side);
    float tMax = FLT_MAX;
    bool traced = true;
    if (mode == 2) {
        // As lights.glsl's transmittanceTo: a light at or behind the offset
        // origin lies within the surface's error bound and needs no shadow ray.
        vec3 light = hit.position + lightDistance * dir;
        vec3 shadowDir = light - origin;
        traced = dot(shadowDir, side) > 0.0;
        if (traced) {
            tMax = length(shadowDir);
            dir = shadowDir / tMax;
        }
    }
    HitId second = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true, 0u);
    bool anyHit = false;
    if (traced) {
        second = findClosest(Ray(origin, dir), tMax);
        anyHit = traceAny(Ray(origin, dir), tMax);
    }
    outputs[o] = 1.0;
    outputs[o + 1u] = second.shape == SHAPE_NONE ? 0.0 : 1.0;
    outputs[o + 2u] = second.shape == SHAPE_NONE ? 0.0 : second.t;
    outputs[o + 3u] = origin.x;
    outputs[o + 4u] = origin.y;
    outputs[o + 5u] = origin.z;
    outputs[o + 6u] = dir.x;
    outputs[o + 7u] = dir.y;
    outputs[o + 8u] = dir.z;
    outputs[o + 9u] = dot(dir, side);
    outputs[o + 10u] = hit.position.x;
    outputs[o + 11u] = hit.position.y;
    outputs[o + 12u] = hit.position.z;
    outputs[o + 13u] = frontFace ? 1.0 : 0.0;
    outputs[o + 14u] = anyHit ? 1.0 : 0.0;
}
