// Robust ray-primitive tests in float32 (docs/robustness.md). Each returns
// the hit distance in (0, tMax) or false. Directions are unit length.
//
// Every value that decides a hit is `precise`: SPIR-V lets a driver contract
// a * b + c into a fused multiply-add unless told not to, and Mesa 26's
// lavapipe does (Mesa 22 and 25 never fused). Fusing some products and not
// others breaks the consistency these tests rely on (the sphere's
// discriminant at grazing incidence, the watertight edge functions):
// measured on Mesa 26.1, grazing rays missed spheres they hit on Mesa 25 and
// rays inside a diffuse sphere lost energy. `precise` gives every driver the
// arithmetic the tests were validated with.
#ifndef VKRT_INTERSECT_GLSL
#define VKRT_INTERSECT_GLSL

// Sphere: the discriminant as r^2 - |f - (f.d)d|^2 and the near root as c/q
// with q = b + sign(b) sqrt(disc) avoid catastrophic cancellation (Haines et
// al., "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems
// ch. 7). The naive form misclassifies near-silhouette rays from afar.
// `local` is the hit point relative to the centre, l -/+ sqrt(disc) d, which
// keeps its accuracy when the sphere is small against its distance (the
// point origin + t d would not). `front`: the ray starts outside, decided by
// which root was taken rather than by the sign of dot(normal, d), which
// rounding flips at grazing angles.
bool intersectSphere(Sphere s, Ray r, float tMax, out float tHit, out vec3 local, out bool front)
{
    precise vec3 f = r.origin - s.center;
    precise float b = -dot(f, r.dir);
    precise vec3 l = f + b * r.dir;
    precise float r2 = s.radius * s.radius;
    precise float disc = r2 - dot(l, l);
    if (disc < 0.0)
        return false;
    precise float c = dot(f, f) - r2;
    precise float rootDisc = sqrt(disc);
    precise float q = b + (b >= 0.0 ? rootDisc : -rootDisc);
    precise float tNear = c / q;
    precise float tFar = q;
    if (tNear > tFar) {
        float tmp = tNear;
        tNear = tFar;
        tFar = tmp;
    }
    front = tNear > 0.0;
    tHit = front ? tNear : tFar;
    precise vec3 hitLocal = l + (front ? -rootDisc : rootDisc) * r.dir;
    local = hitLocal;
    return tHit > 0.0 && tHit < tMax;
}

int argMax3(vec3 v) { return (v.x >= v.y && v.x >= v.z) ? 0 : (v.y >= v.z ? 1 : 2); }
int argMin3(vec3 v) { return (v.x <= v.y && v.x <= v.z) ? 0 : (v.y <= v.z ? 1 : 2); }

// Slab test that stays defined when a direction component is exactly zero
// (0 * inf would be NaN): such an axis either rejects the ray or imposes no
// limit. tFar is widened by 1 + 2*gamma(3) so that rounding cannot open a gap
// at edges (Ize, "Robust BVH Ray Traversal", JCGT 2013).
bool intersectBox(Box b, Ray r, float tMax, out float tHit, out vec3 normal, out bool front)
{
    bvec3 parallel = equal(r.dir, vec3(0.0));
    bvec3 outside = bvec3(uvec3(lessThan(r.origin, b.lower)) | uvec3(greaterThan(r.origin, b.upper)));
    if (any(bvec3(uvec3(parallel) & uvec3(outside))))
        return false;
    vec3 invDir = 1.0 / r.dir;
    vec3 tLower = (b.lower - r.origin) * invDir;
    vec3 tUpper = (b.upper - r.origin) * invDir;
    vec3 tNearAxis = mix(min(tLower, tUpper), vec3(-FLT_MAX), parallel);
    vec3 tFarAxis = mix(max(tLower, tUpper), vec3(FLT_MAX), parallel);
    float tNear = max(tNearAxis.x, max(tNearAxis.y, tNearAxis.z));
    const float gamma3 = 3.0 * 5.96046448e-8 / (1.0 - 3.0 * 5.96046448e-8);
    float tFarExact = min(tFarAxis.x, min(tFarAxis.y, tFarAxis.z));
    float tFar = tFarExact * (1.0 + 2.0 * gamma3);
    if (tNear > tFar)
        return false;
    bool entering = tNear > 0.0;
    front = entering;
    tHit = entering ? tNear : tFar;
    if (!(tHit > 0.0 && tHit < tMax))
        return false;
    // The face hit lies on the axis that set the entry (or exit) distance;
    // its outward normal points against the ray on entry, along it on exit.
    int axis = entering ? argMax3(tNearAxis) : argMin3(tFarAxis);
    normal = vec3(0.0);
    normal[axis] = entering ? -sign(r.dir[axis]) : sign(r.dir[axis]);
    return true;
}

// Per-ray set-up of the watertight triangle test.
struct TriangleRay {
    int kx, ky, kz;
    vec3 shear; // (Sx, Sy, Sz)
};

TriangleRay triangleRaySetup(Ray r)
{
    vec3 a = abs(r.dir);
    int kz = (a.x > a.y) ? ((a.x > a.z) ? 0 : 2) : ((a.y > a.z) ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (r.dir[kz] < 0.0) {
        int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    return TriangleRay(kx, ky, kz, vec3(r.dir[kx] / r.dir[kz], r.dir[ky] / r.dir[kz], 1.0 / r.dir[kz]));
}

// Watertight ray/triangle test (Woop, Benthin & Wald, JCGT 2013): edge
// functions are evaluated in a ray-aligned frame so that a ray through a shared
// edge hits at least one of the two triangles. Both faces are hit.
// Degenerate triangles are never hit: det == 0 catches most, and a zero
// cross product the rest (sheared edge functions of exactly collinear
// vertices round to a tiny nonzero area). `bary` weighs v0, v1, v2.
bool intersectTriangle(vec3 v0, vec3 v1, vec3 v2, Ray r, TriangleRay tr, float tMax, out float tHit, out vec3 bary)
{
    precise vec3 A = v0 - r.origin;
    precise vec3 B = v1 - r.origin;
    precise vec3 C = v2 - r.origin;
    precise float Ax = A[tr.kx] - tr.shear.x * A[tr.kz];
    precise float Ay = A[tr.ky] - tr.shear.y * A[tr.kz];
    precise float Bx = B[tr.kx] - tr.shear.x * B[tr.kz];
    precise float By = B[tr.ky] - tr.shear.y * B[tr.kz];
    precise float Cx = C[tr.kx] - tr.shear.x * C[tr.kz];
    precise float Cy = C[tr.ky] - tr.shear.y * C[tr.kz];
    precise float U = Cx * By - Cy * Bx;
    precise float V = Ax * Cy - Ay * Cx;
    precise float W = Bx * Ay - By * Ax;
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0))
        return false;
    precise float det = U + V + W;
    if (det == 0.0)
        return false;
    precise float T = U * (tr.shear.z * A[tr.kz]) + V * (tr.shear.z * B[tr.kz]) + W * (tr.shear.z * C[tr.kz]);
    // t = T / det must lie in (0, tMax); compare before dividing to keep signs exact.
    precise float signedT = det < 0.0 ? -T : T;
    precise float absDet = abs(det);
    precise float tLimit = tMax * absDet;
    if (signedT <= 0.0 || signedT >= tLimit)
        return false;
    precise vec3 area = cross(v1 - v0, v2 - v0);
    if (all(equal(area, vec3(0.0))))
        return false;
    tHit = T / det;
    bary = vec3(U, V, W) / det;
    return tHit > 0.0 && tHit < tMax;
}

bool intersectPlane(Plane p, Ray r, float tMax, out float tHit)
{
    precise float denom = dot(r.dir, p.normal);
    if (denom == 0.0)
        return false;
    precise float along = dot(p.point - r.origin, p.normal);
    tHit = along / denom;
    return tHit > 0.0 && tHit < tMax;
}

#endif
