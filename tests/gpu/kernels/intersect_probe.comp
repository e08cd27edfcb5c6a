// One ray against one primitive through the renderer's intersection tests
// (lib/intersect.glsl). inputs[17i ..] = kind (0 sphere, 1 box, 2 triangle,
// 3 plane), 9 shape parameters (sphere: center, radius; box: lower, upper;
// triangle: v0, v1, v2; plane: point, normal), ray origin, ray direction, tMax.
// outputs[5i ..] = hit flag, t (0 on a miss), box normal (0 otherwise).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "probe.glsl"
#include "lib/intersect.glsl"

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= invocationCount)
        return;
    uint base = 17u * i;
    int kind = int(inputs[base]);
    vec3 p0 = vec3(inputs[base + 1u], inputs[base + 2u], inputs[base + 3u]);
    vec3 p1 = vec3(inputs[base + 4u], inputs[base + 5u], inputs[base + 6u]);
    vec3 p2 = vec3(inputs[base + 7u], inputs[base + 8u], inputs[base + 9u]);
    Ray r = Ray(vec3(inputs[base + 10u], inputs[base + 11u], inputs[base + 12u]),
                vec3(inputs[base + 13u], inputs[base + 14u], inputs[base + 15u]));
    float tMax = inputs[base + 16u];

    bool hit = false;
    float t = 0.0;
    vec3 normal = vec3(0.0);
    vec3 detail;
    bool front;
    if (kind == 0) {
        hit = intersectSphere(Sphere(p0, p1.x, 0u), r, tMax, t, detail, front);
    } else if (kind == 1) {
        hit = intersectBox(Box(p0, 0u, p1), r, tMax, t, normal, front);
    } else if (kind == 2) {
        hit = intersectTriangle(p0, p1, p2, r, triangleRaySetup(r), tMax, t, detail);
    } else {
        hit = intersectPlane(Plane(p0, 0u, p1), r, tMax, t);
    }
    uint o = 5u * i;
    outputs[o] = hit ? 1.0 : 0.0;
    outputs[o + 1u] = hit ? t : 0.0;
    outputs[o + 2u] = hit ? normal.x : 0.0;
    outputs[o + 3u] = hit ? normal.y : 0.0;
    outputs[o + 4u] = hit ? normal.z : 0.0;
}
