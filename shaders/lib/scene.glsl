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
    vec3 normal;  // unit geometric normal; outward for spheres and boxes
    vec3 shading; // unit shading normal, on the side of `normal` (meshes with vertex normals; else = normal)
    bool front;   // the ray arrived on the side `normal` points to
    uint material;
    int shape;
    uint index;
    uint emitter; // the Emitter this surface is (emissive meshes), else NO_EMITTER
#ifdef VKRT_HAS_TEXTURES
    // Texture coordinates (docs/scene-format.md, "Texture coordinates"), the
    // uv area per world area there (the ray cone's texel density), and the
    // world direction of increasing u with the bitangent's handedness
    // (bitangent = tangent.w cross(shading, tangent.xyz)) for normal maps.
    vec2 uv;
    float uvDensity;
    vec4 tangent;
#endif
};

const uint NO_EMITTER = 0xffffffffu;

bool hitsLight(SurfaceHit hit) { return hit.shape >= SHAPE_LIGHT; }

// The shading normal on the side of n (the geometric normal facing the ray);
// only meshes with vertex normals have one of their own, and the other
// variants never read the field.
vec3 shadingSide(SurfaceHit hit, vec3 n)
{
#ifdef VKRT_HAS_SHADING_NORMALS
    return hit.front ? hit.shading : -hit.shading;
#else
    return n;
#endif
}

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
    uint primitive; // a mesh's triangle (its leaf slot); 0 for other kinds
};

// ------------------------------------------------------ texture coordinates
// Every shape's uv, texel density and tangent (docs/scene-format.md,
// "Texture coordinates"). The tangent is dp/du's direction, w the sign that
// makes w cross(n, tangent) point along dp/dv.

#ifdef VKRT_HAS_TEXTURES
// Spheres: longitude and latitude about the world y axis, u = 0.5 at +z and
// growing towards +x, v from 0 at the bottom pole to 1 at the top.
// du dv / dA = 1 / (2 pi^2 r^2 cos(latitude)).
void sphereUv(vec3 n, float radius, inout SurfaceHit hit)
{
    float cosLatitude = sqrt(max(1.0 - n.y * n.y, 0.0));
    hit.uv = vec2(0.5 + atan(n.x, n.z) * (0.5 * INV_PI), 0.5 + asin(clamp(n.y, -1.0, 1.0)) * INV_PI);
    hit.uvDensity = 1.0 / (2.0 * PI * PI * radius * radius * max(cosLatitude, 1e-3));
    vec3 east = vec3(n.z, 0.0, -n.x);
    hit.tangent = vec4(cosLatitude > 1e-6 ? east / cosLatitude : vec3(1.0, 0.0, 0.0), 1.0);
}

// Boxes: each face's uv spans [0, 1]^2 over the face, upright seen from
// outside (v up along +y on the side faces; on the top v grows towards -z,
// on the bottom towards +z).
void boxUv(Box b, vec3 faceNormal, vec3 p, inout SurfaceHit hit)
{
    vec3 extent = b.upper - b.lower;
    vec3 f = (p - b.lower) / extent; // 0 ... 1 across the box
    if (faceNormal.x != 0.0) {
        float s = faceNormal.x;
        hit.uv = vec2(s > 0.0 ? 1.0 - f.z : f.z, f.y);
        hit.uvDensity = 1.0 / (extent.z * extent.y);
        hit.tangent = vec4(0.0, 0.0, -s, 1.0);
    } else if (faceNormal.y != 0.0) {
        float s = faceNormal.y;
        hit.uv = vec2(f.x, s > 0.0 ? 1.0 - f.z : f.z);
        hit.uvDensity = 1.0 / (extent.x * extent.z);
        hit.tangent = vec4(1.0, 0.0, 0.0, 1.0);
    } else {
        float s = faceNormal.z;
        hit.uv = vec2(s > 0.0 ? f.x : 1.0 - f.x, f.y);
        hit.uvDensity = 1.0 / (extent.x * extent.y);
        hit.tangent = vec4(s, 0.0, 0.0, 1.0);
    }
}

// Planes: world distances from the plane's point along two axes in it, one
// uv unit per scene unit: tangent = normalize(cross(+y, n)) (+x for
// horizontal planes), bitangent = cross(n, tangent).
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

// Triangles with uvs uv0..uv2 at world edges e1 = v1 - v0, e2 = v2 - v0:
// uv by barycentrics, density from the two areas, the tangent from the uv
// derivatives (Lengyel 2001) when no vertex tangents are given.
void triangleUv(vec3 bary, vec2 uv0, vec2 uv1, vec2 uv2, vec3 e1, vec3 e2, inout SurfaceHit hit)
{
    hit.uv = bary.x * uv0 + bary.y * uv1 + bary.z * uv2;
    vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
    float uvCross = d1.x * d2.y - d1.y * d2.x;
    vec3 worldCross = cross(e1, e2);
    float worldArea = length(worldCross);
    hit.uvDensity = worldArea > 0.0 ? abs(uvCross) / worldArea : 0.0;
    vec3 dpdu = (d2.y * e1 - d1.y * e2) * sign(uvCross);
    vec3 dpdv = (d1.x * e2 - d2.x * e1) * sign(uvCross);
    float len = length(dpdu);
    hit.tangent = vec4(len > 0.0 && !isinf(len) ? dpdu / len : normalize(e1),
                       dot(cross(worldCross, dpdu), dpdv) < 0.0 ? -1.0 : 1.0);
}
#endif

// ------------------------------------------------------------------ spheres

#ifdef VKRT_HAS_SPHERES
void closestOneSphere(Ray r, uint i, inout HitId best)
{
    float t;
    vec3 local;
    bool front;
    if (intersectSphere(spheres[i], r, best.t, t, local, front))
        best = HitId(SHAPE_SPHERE, i, t, local, front, 0u);
}

bool anyHitOneSphere(Ray r, uint i, float tMax)
{
    float t;
    vec3 local;
    bool front;
    return intersectSphere(spheres[i], r, tMax, t, local, front);
}
#endif

void closestSphere(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_SPHERES
    for (uint i = 0u; i < u.sphereCount; ++i) {
        ++g_loopIterations;
        closestOneSphere(r, i, best);
    }
#endif
}

bool anyHitSphere(Ray r, float tMax)
{
#ifdef VKRT_HAS_SPHERES
    for (uint i = 0u; i < u.sphereCount; ++i) {
        ++g_loopIterations;
        if (anyHitOneSphere(r, i, tMax))
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
#ifdef VKRT_HAS_TEXTURES
    sphereUv(hit.normal, s.radius, hit);
#endif
#endif
}

// -------------------------------------------------------------------- boxes

#ifdef VKRT_HAS_BOXES
void closestOneBox(Ray r, uint i, inout HitId best)
{
    float t;
    vec3 n;
    bool front;
    if (intersectBox(boxes[i], r, best.t, t, n, front))
        best = HitId(SHAPE_BOX, i, t, n, front, 0u);
}

bool anyHitOneBox(Ray r, uint i, float tMax)
{
    float t;
    vec3 n;
    bool front;
    return intersectBox(boxes[i], r, tMax, t, n, front);
}
#endif

void closestBox(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_BOXES
    for (uint i = 0u; i < u.boxCount; ++i) {
        ++g_loopIterations;
        closestOneBox(r, i, best);
    }
#endif
}

bool anyHitBox(Ray r, float tMax)
{
#ifdef VKRT_HAS_BOXES
    for (uint i = 0u; i < u.boxCount; ++i) {
        ++g_loopIterations;
        if (anyHitOneBox(r, i, tMax))
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
#ifdef VKRT_HAS_TEXTURES
    boxUv(b, id.detail, hit.position, hit);
#endif
#endif
}

// ---------------------------------------------------------------- triangles

#ifdef VKRT_HAS_TRIANGLES
void closestOneTriangle(Ray r, TriangleRay tr, uint i, inout HitId best)
{
    float t;
    vec3 bary;
    Triangle tri = triangles[i];
    if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, best.t, t, bary))
        best = HitId(SHAPE_TRIANGLE, i, t, bary, true, 0u);
}

bool anyHitOneTriangle(Ray r, TriangleRay tr, uint i, float tMax)
{
    float t;
    vec3 bary;
    Triangle tri = triangles[i];
    return intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, tMax, t, bary);
}
#endif

void closestTriangle(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLES
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleCount; ++i) {
        ++g_loopIterations;
        closestOneTriangle(r, tr, i, best);
    }
#endif
}

bool anyHitTriangle(Ray r, float tMax)
{
#ifdef VKRT_HAS_TRIANGLES
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleCount; ++i) {
        ++g_loopIterations;
        if (anyHitOneTriangle(r, tr, i, tMax))
            return true;
    }
#endif
    return false;
}

// How far off a triangle's plane a point must be for the watertight test
// (lib/intersect.glsl) to tell its side: the test subtracts the ray origin
// from each vertex and shears the result, rounding at the scale of the
// vertices, not of the hit point (gamma(5) of the largest vertex coordinate,
// after pbrt-v4's deltaX/deltaY, section 6.8.4). A ray spawned closer than
// that, leaving at a grazing angle, was measured hitting its own triangle
// (Mesa 26.1, tests/gpu/intersection_probe_test.cpp).
vec3 triangleTestError(vec3 v0, vec3 v1, vec3 v2)
{
    vec3 largest = max(max(abs(v0), abs(v1)), abs(v2));
    return vec3(gammaBound(5) * max(largest.x, max(largest.y, largest.z)));
}

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

// ------------------------------------------------------------------- planes

void closestPlane(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_PLANES
    for (uint i = 0u; i < u.planeCount; ++i) {
        ++g_loopIterations;
        float t;
        if (intersectPlane(planes[i], r, best.t, t))
            best = HitId(SHAPE_PLANE, i, t, vec3(0.0), true, 0u);
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
#ifdef VKRT_HAS_TEXTURES
    planeUv(p, hit.position, hit);
#endif
#endif
}

// ------------------------------------------------------------------- meshes
// A mesh instance is traversed in its own coordinates: the ray is moved
// into object space (the parameter t stays the same, so hits of different
// instances compare directly), and its geometry's BVH is walked with a
// bounded stack, near child first, skipping nodes beyond the closest hit.
// Every node visit and triangle test counts as a loop iteration.

#ifdef VKRT_HAS_MESHES
Ray rayToObject(Mesh mesh, Ray r)
{
    vec3 o = vec3(dot(mesh.toObject0.xyz, r.origin) + mesh.toObject0.w,
                  dot(mesh.toObject1.xyz, r.origin) + mesh.toObject1.w,
                  dot(mesh.toObject2.xyz, r.origin) + mesh.toObject2.w);
    vec3 d = vec3(dot(mesh.toObject0.xyz, r.dir), dot(mesh.toObject1.xyz, r.dir), dot(mesh.toObject2.xyz, r.dir));
    return Ray(o, d);
}

vec3 objectToWorldPoint(Mesh mesh, vec3 p)
{
    return vec3(dot(mesh.toWorld0.xyz, p) + mesh.toWorld0.w, dot(mesh.toWorld1.xyz, p) + mesh.toWorld1.w,
                dot(mesh.toWorld2.xyz, p) + mesh.toWorld2.w);
}

// Normals transform by the inverse transpose: n_world = transpose(toObject) n.
vec3 objectToWorldNormal(Mesh mesh, vec3 n)
{
    return mesh.toObject0.xyz * n.x + mesh.toObject1.xyz * n.y + mesh.toObject2.xyz * n.z;
}

// The closest (anyHit: any) triangle of mesh instance `index` before best.t
// (tMax). Returns whether one was found.
bool traverseMesh(Ray worldRay, uint index, bool anyHit, float tMax, inout HitId best)
{
    Mesh mesh = meshes[index];
    Ray r = rayToObject(mesh, worldRay);
    TriangleRay tr = triangleRaySetup(r);
    BvhRay br = bvhRaySetup(r);
    uint stackNode[BVH_STACK_SIZE];
    float stackEntry[BVH_STACK_SIZE];
    uint depth = 0u;
    uint node = 0u; // relative to mesh.root
    float tEntry;
    BvhNode root = meshNodes[mesh.root];
    bool visiting = entersBox(root.lower, root.upper, br, anyHit ? tMax : best.t, tEntry);
    bool found = false;
    while (visiting) {
        ++g_loopIterations;
        BvhNode n = meshNodes[mesh.root + node];
        float limit = anyHit ? tMax : best.t;
        bool descend = false;
        if (n.count > 0u) {
            for (uint k = 0u; k < n.count; ++k) {
                ++g_loopIterations;
                uint slot = n.first + k;
                MeshTriangle tri = meshTriangles[mesh.firstTriangle + slot];
                float t;
                vec3 bary;
                if (intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, limit, t, bary)) {
                    found = true;
                    if (anyHit)
                        return true;
                    best = HitId(SHAPE_MESH, index, t, bary, true, slot);
                    limit = t;
                }
            }
        } else {
            BvhNode a = meshNodes[mesh.root + n.first];
            BvhNode b = meshNodes[mesh.root + n.first + 1u];
            float ta, tb;
            bool ha = entersBox(a.lower, a.upper, br, limit, ta);
            bool hb = entersBox(b.lower, b.upper, br, limit, tb);
            if (ha && hb) {
                bool aFirst = ta <= tb;
                stackNode[depth] = aFirst ? n.first + 1u : n.first;
                stackEntry[depth] = aFirst ? tb : ta;
                ++depth;
                node = aFirst ? n.first : n.first + 1u;
                descend = true;
            } else if (ha || hb) {
                node = ha ? n.first : n.first + 1u;
                descend = true;
            }
        }
        if (!descend) {
            visiting = false;
            while (depth > 0u) {
                ++g_loopIterations;
                --depth;
                if (stackEntry[depth] <= (anyHit ? tMax : best.t)) {
                    node = stackNode[depth];
                    visiting = true;
                    break;
                }
            }
        }
    }
    return found;
}

void closestOneMesh(Ray r, uint i, inout HitId best) { traverseMesh(r, i, false, 0.0, best); }

bool anyHitOneMesh(Ray r, uint i, float tMax)
{
    HitId unused = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true, 0u);
    return traverseMesh(r, i, true, tMax, unused);
}
#endif

void closestMesh(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_MESHES
    for (uint i = 0u; i < u.meshCount; ++i) {
        ++g_loopIterations;
        closestOneMesh(r, i, best);
    }
#endif
}

bool anyHitMesh(Ray r, float tMax)
{
#ifdef VKRT_HAS_MESHES
    for (uint i = 0u; i < u.meshCount; ++i) {
        ++g_loopIterations;
        if (anyHitOneMesh(r, i, tMax))
            return true;
    }
#endif
    return false;
}

#ifdef VKRT_HAS_MESH_UVS
vec3 objectToWorldVector(Mesh mesh, vec3 v)
{
    return vec3(dot(mesh.toWorld0.xyz, v), dot(mesh.toWorld1.xyz, v), dot(mesh.toWorld2.xyz, v));
}

// A mesh triangle's uv, density and tangent: the file's uvs (zero without),
// the vertex tangents interpolated where the geometry has them.
void describeMeshUv(Mesh mesh, HitId id, MeshTriangle tri, inout SurfaceHit hit)
{
    uint index = mesh.firstTriangle + id.primitive;
    // (No ?: between a buffer's struct and a local one: glslang emits invalid SPIR-V for it.)
    vec2 uv0 = vec2(0.0), uv1 = vec2(0.0), uv2 = vec2(0.0);
    if ((mesh.flags & MESH_FLAG_UVS) != 0u) {
        uv0 = meshUvs[index].uv0;
        uv1 = meshUvs[index].uv1;
        uv2 = meshUvs[index].uv2;
    }
    triangleUv(id.detail, uv0, uv1, uv2, objectToWorldVector(mesh, tri.v1 - tri.v0),
               objectToWorldVector(mesh, tri.v2 - tri.v0), hit);
#ifdef VKRT_HAS_MESH_TANGENTS
    if ((mesh.flags & MESH_FLAG_TANGENTS) != 0u) {
        MeshTangents t = meshTangents[index];
        vec3 object = id.detail.x * t.t0.xyz + id.detail.y * t.t1.xyz + id.detail.z * t.t2.xyz;
        vec3 world = objectToWorldVector(mesh, object);
        float len = length(world);
        // A mirroring transform flips the bitangent's handedness.
        float mirror = dot(cross(mesh.toWorld0.xyz, mesh.toWorld1.xyz), mesh.toWorld2.xyz) < 0.0 ? -1.0 : 1.0;
        if (len > 0.0 && !isinf(len))
            hit.tangent = vec4(world / len, (t.t0.w < 0.0 ? -1.0 : 1.0) * mirror);
    }
#endif
}
#endif

void describeMesh(Ray r, HitId id, inout SurfaceHit hit)
{
#ifdef VKRT_HAS_MESHES
    // Interpolated in object space (error gamma(7) sum |b_i v_i|, as for
    // triangles), then transformed: the transform's own rounding is gamma(3)
    // of |M| |p| + |t| per coordinate, and it scales the object-space error
    // by |M| (pbrt-v4 section 6.8.5).
    Mesh mesh = meshes[id.index];
    MeshTriangle tri = meshTriangles[mesh.firstTriangle + id.primitive];
    precise vec3 b0 = id.detail.x * tri.v0, b1 = id.detail.y * tri.v1, b2 = id.detail.z * tri.v2;
    precise vec3 p = b0 + b1 + b2;
    vec3 objectError = gammaBound(7) * (abs(b0) + abs(b1) + abs(b2)) + triangleTestError(tri.v0, tri.v1, tri.v2);
    mat3 absM = mat3(abs(vec3(mesh.toWorld0.x, mesh.toWorld1.x, mesh.toWorld2.x)),
                     abs(vec3(mesh.toWorld0.y, mesh.toWorld1.y, mesh.toWorld2.y)),
                     abs(vec3(mesh.toWorld0.z, mesh.toWorld1.z, mesh.toWorld2.z)));
    vec3 absT = abs(vec3(mesh.toWorld0.w, mesh.toWorld1.w, mesh.toWorld2.w));
    hit.position = objectToWorldPoint(mesh, p);
    hit.error = (1.0 + gammaBound(3)) * (absM * objectError) + gammaBound(3) * (absM * abs(p) + absT);
    hit.normal = normalize(objectToWorldNormal(mesh, cross(tri.v1 - tri.v0, tri.v2 - tri.v0)));
    hit.front = dot(hit.normal, r.dir) < 0.0;
    hit.shading = hit.normal;
#ifdef VKRT_HAS_MESH_NORMALS
    if ((mesh.flags & MESH_FLAG_NORMALS) != 0u) {
        MeshNormals normals = meshNormals[mesh.firstNormals + id.primitive];
        vec3 ns = id.detail.x * normals.n0 + id.detail.y * normals.n1 + id.detail.z * normals.n2;
        vec3 world = objectToWorldNormal(mesh, ns);
        float len = length(world);
        // A zero or vanishing interpolated normal keeps the face normal.
        if (len > 0.0 && !isinf(len))
            hit.shading = faceforward(world / len, -hit.normal, world);
    }
#endif
    hit.material = mesh.material;
#ifdef VKRT_HAS_MESH_MATERIALS
    if ((mesh.flags & MESH_FLAG_MATERIALS) != 0u)
        hit.material = meshMaterials[mesh.firstTriangle + id.primitive];
#endif
#ifdef VKRT_HAS_MESH_UVS
    describeMeshUv(mesh, id, tri, hit);
#endif
#ifdef VKRT_HAS_EMITTERS
    if ((mesh.flags & MESH_FLAG_EMISSIVE) != 0u)
        hit.emitter = mesh.firstEmitter + id.primitive;
#endif
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

#ifdef VKRT_HAS_TRIANGLE_LIGHTS
void closestOneTriangleLight(Ray r, TriangleRay tr, uint i, inout HitId best)
{
    float t;
    vec3 bary;
    TriangleLight light = triangleLights[i];
    if (intersectTriangle(light.v0, light.v1, light.v2, r, tr, best.t, t, bary))
        best = HitId(SHAPE_LIGHT + LIGHT_TRIANGLE, i, t, bary, true, 0u);
}

bool anyHitOneTriangleLight(Ray r, TriangleRay tr, uint i, float tMax)
{
    float t;
    vec3 bary;
    TriangleLight light = triangleLights[i];
    return intersectTriangle(light.v0, light.v1, light.v2, r, tr, tMax, t, bary);
}
#endif

void closestTriangleLight(Ray r, inout HitId best)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        closestOneTriangleLight(r, tr, i, best);
    }
#endif
}

bool anyHitTriangleLight(Ray r, float tMax)
{
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    TriangleRay tr = triangleRaySetup(r);
    for (uint i = 0u; i < u.triangleLightCount; ++i) {
        ++g_loopIterations;
        if (anyHitOneTriangleLight(r, tr, i, tMax))
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

#ifdef VKRT_HAS_MESHES
// One record of the top-level BVH: TOP_REF(kind, index), shared/SceneTypes.h.
void closestRecord(Ray r, TriangleRay tr, uint ref, inout HitId best)
{
    int kind = int(ref >> TOP_REF_INDEX_BITS);
    uint i = ref & TOP_REF_MAX_INDEX;
#ifdef VKRT_HAS_SPHERES
    if (kind == SHAPE_SPHERE)
        closestOneSphere(r, i, best);
#endif
#ifdef VKRT_HAS_BOXES
    if (kind == SHAPE_BOX)
        closestOneBox(r, i, best);
#endif
#ifdef VKRT_HAS_TRIANGLES
    if (kind == SHAPE_TRIANGLE)
        closestOneTriangle(r, tr, i, best);
#endif
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    if (kind == SHAPE_LIGHT + LIGHT_TRIANGLE)
        closestOneTriangleLight(r, tr, i, best);
#endif
    if (kind == SHAPE_MESH)
        closestOneMesh(r, i, best);
}

bool anyHitRecord(Ray r, TriangleRay tr, uint ref, float tMax)
{
    int kind = int(ref >> TOP_REF_INDEX_BITS);
    uint i = ref & TOP_REF_MAX_INDEX;
#ifdef VKRT_HAS_SPHERES
    if (kind == SHAPE_SPHERE)
        return anyHitOneSphere(r, i, tMax);
#endif
#ifdef VKRT_HAS_BOXES
    if (kind == SHAPE_BOX)
        return anyHitOneBox(r, i, tMax);
#endif
#ifdef VKRT_HAS_TRIANGLES
    if (kind == SHAPE_TRIANGLE)
        return anyHitOneTriangle(r, tr, i, tMax);
#endif
#ifdef VKRT_HAS_TRIANGLE_LIGHTS
    if (kind == SHAPE_LIGHT + LIGHT_TRIANGLE)
        return anyHitOneTriangleLight(r, tr, i, tMax);
#endif
    if (kind == SHAPE_MESH)
        return anyHitOneMesh(r, i, tMax);
    return false;
}

// The top-level BVH over every bounded record (planes stay a list): the
// closest hit, or (anyHit) whether anything lies before tMax.
bool traverseTop(Ray r, bool anyHit, float tMax, inout HitId best)
{
    TriangleRay tr = triangleRaySetup(r);
    BvhRay br = bvhRaySetup(r);
    uint stackNode[BVH_STACK_SIZE];
    float stackEntry[BVH_STACK_SIZE];
    uint depth = 0u;
    uint node = 0u;
    float tEntry;
    BvhNode root = topNodes[0];
    bool visiting = entersBox(root.lower, root.upper, br, anyHit ? tMax : best.t, tEntry);
    while (visiting) {
        ++g_loopIterations;
        BvhNode n = topNodes[node];
        bool descend = false;
        if (n.count > 0u) {
            for (uint k = 0u; k < n.count; ++k) {
                ++g_loopIterations;
                uint ref = topRefs[n.first + k];
                if (anyHit) {
                    if (anyHitRecord(r, tr, ref, tMax))
                        return true;
                } else {
                    closestRecord(r, tr, ref, best);
                }
            }
        } else {
            float limit = anyHit ? tMax : best.t;
            BvhNode a = topNodes[n.first];
            BvhNode b = topNodes[n.first + 1u];
            float ta, tb;
            bool ha = entersBox(a.lower, a.upper, br, limit, ta);
            bool hb = entersBox(b.lower, b.upper, br, limit, tb);
            if (ha && hb) {
                bool aFirst = ta <= tb;
                stackNode[depth] = aFirst ? n.first + 1u : n.first;
                stackEntry[depth] = aFirst ? tb : ta;
                ++depth;
                node = aFirst ? n.first : n.first + 1u;
                descend = true;
            } else if (ha || hb) {
                node = ha ? n.first : n.first + 1u;
                descend = true;
            }
        }
        if (!descend) {
            visiting = false;
            while (depth > 0u) {
                ++g_loopIterations;
                --depth;
                if (stackEntry[depth] <= (anyHit ? tMax : best.t)) {
                    node = stackNode[depth];
                    visiting = true;
                    break;
                }
            }
        }
    }
    return false;
}
#endif

// The closest hit over every kind, shapes first, in registry order.
// With meshes, the top-level BVH replaces the per-kind loops (planes, unbounded, stay a loop).
HitId findClosest(Ray r, float tMax)
{
    HitId best = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true, 0u);
#ifdef VKRT_HAS_MESHES
    if (u.topNodeCount > 0u) {
        closestPlane(r, best);
        traverseTop(r, false, tMax, best);
        return best;
    }
#endif
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
#ifdef VKRT_HAS_MESHES
    hit.emitter = NO_EMITTER;
#endif
    hit.shape = id.shape;
    hit.index = id.index;
    hit.material = 0u;
#ifdef VKRT_HAS_TEXTURES
    hit.uv = vec2(0.0);
    hit.uvDensity = 0.0;
    hit.tangent = vec4(1.0, 0.0, 0.0, 1.0);
#endif
    VKRT_SHAPE_KINDS(VKRT_DESCRIBE_SHAPE)
    VKRT_LIGHT_KINDS(VKRT_DESCRIBE_LIGHT)
    // Meshes set their own shading normal; normal maps may change it later.
#ifdef VKRT_HAS_MESHES
    if (id.shape != SHAPE_MESH)
#endif
        hit.shading = hit.normal;
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
#ifdef VKRT_HAS_MESHES
    if (u.topNodeCount > 0u) {
        if (anyHitPlane(r, tMax))
            return true;
        HitId unused = HitId(SHAPE_NONE, 0u, tMax, vec3(0.0), true, 0u);
        return traverseTop(r, true, tMax, unused);
    }
#endif
    VKRT_SHAPE_KINDS(VKRT_ANY_HIT_OF_KIND)
    VKRT_LIGHT_KINDS(VKRT_ANY_HIT_OF_KIND)
    return false;
}

#endif
