// Mesh instances (`shape = "mesh"`): one record per instance, naming its
// geometry's BVH and triangles (lib/bindings.glsl: meshNodes, meshTriangles
// and the per-triangle attributes) and its transforms.
#ifndef VKRT_SHAPE_MESH_GLSL
#define VKRT_SHAPE_MESH_GLSL

#ifdef VKRT_HAS_MESHES
VKRT_SCENE_ARRAY(BINDING_MESHES, MeshBlock, Mesh, meshes, UNIFORM_MESHES)
#endif

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

#include "lib/alpha.glsl"

#ifndef VKRT_ACCEL_DRIVER
// The closest (anyHit: any) triangle of mesh instance `index` before best.t
// (tMax) that its alpha test keeps (lib/alpha.glsl). Returns whether one was found.
bool traverseMesh(Ray worldRay, uint index, bool anyHit, float tMax, inout HitId best)
{
    Mesh mesh = meshes[index];
    Ray r = rayToObject(mesh, worldRay);
    TriangleRay tr = triangleRaySetup(r);
    BvhRay br = bvhRaySetup(r);
    VKRT_BVH_WALK_STATE // node: relative to mesh.root
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
#ifdef VKRT_HAS_ALPHA
                    if (!alphaKeeps(worldRay, index, mesh, slot, bary))
                        continue;
#endif
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
            VKRT_BVH_DESCEND(a, b, n.first, br, limit, descend)
        }
        VKRT_BVH_POP_UNLESS(descend, anyHit ? tMax : best.t)
    }
    return found;
}
#endif

#endif

bool hitOneMesh(Ray r, TriangleRay tr, uint i, bool anyHit, float tMax, inout HitId hit)
{
#if defined(VKRT_HAS_MESHES) && !defined(VKRT_ACCEL_DRIVER)
    // The instance's own ray setup: tr is the world ray's. (The driver
    // backend hands mesh triangles to lib/ray_query.glsl, never here.)
    return traverseMesh(r, i, anyHit, tMax, hit);
#else
    return false;
#endif
}

// No loop over the mesh records: a scene with meshes always has the
// top-level BVH (own backend) or the driver's structures, and the loops over
// every kind (lib/scene.glsl) run only without them, when there is no mesh.
// lavapipe inlines every call, so that never-taken loop cost two more copies
// of the mesh walk (closest and any hit): mesh-bunny-glass's cold first frame
// was 4.0-4.2 s on Mesa 25 with them.
VKRT_NO_RECORDS(Mesh)

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
    vec3 e1 = objectToWorldVector(mesh, tri.v1 - tri.v0), e2 = objectToWorldVector(mesh, tri.v2 - tri.v0);
    triangleUv(id.detail, uv0, uv1, uv2, e1, e2, hit);
#ifdef VKRT_HAS_MESH_UVS1
    // The second set's uv and density (its tangents come with the vertex tangents, MeshData::tangentUvSet).
    if ((mesh.flags & MESH_FLAG_UVS1) != 0u) {
        MeshUvs second = meshUvs1[index];
        hit.uv1 = id.detail.x * second.uv0 + id.detail.y * second.uv1 + id.detail.z * second.uv2;
        hit.uvDensity1 = triangleUvDensity(second.uv0, second.uv1, second.uv2, e1, e2);
    }
#endif
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
#ifdef VKRT_HAS_MESH_COLORS
    if ((mesh.flags & MESH_FLAG_COLORS) != 0u) {
        MeshColors c = meshColors[mesh.firstTriangle + id.primitive];
        hit.color = id.detail.x * c.c0 + id.detail.y * c.c1 + id.detail.z * c.c2;
    }
#endif
#ifdef VKRT_HAS_EMITTERS
    if ((mesh.flags & MESH_FLAG_EMISSIVE) != 0u)
        hit.emitter = mesh.firstEmitter + id.primitive;
#endif
#endif
}

#endif
