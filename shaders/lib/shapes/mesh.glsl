// Mesh instances (`shape = "mesh"`): one record per instance, naming its
// geometry's BVH and triangles (lib/bindings.glsl: meshNodes, meshTriangles
// and the per-triangle attributes) and its transforms.
#ifndef VKRT_SHAPE_MESH_GLSL
#define VKRT_SHAPE_MESH_GLSL

#ifdef VKRT_HAS_MESHES
VKRT_SCENE_ARRAY(BINDING_MESHES, MeshBlock, Mesh, meshes, UNIFORM_MESHES)
#define meshes VKRT_SCENE_ITEMS(BINDING_MESHES, MeshBlock, meshes)
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
#ifdef VKRT_PACKET_TRAVERSAL
// The packet walk (Wald et al. 2001): the active lanes of the subgroup walk
// one tree together. The node is subgroup-uniform, so its load is one load
// for every lane, not a gather per lane: on lavapipe with gallivm's
// divergence analysis (Mesa >= 25.1) that is 3.0-4.8x cheaper per node
// (tools/load_probe.cpp, docs/performance.md "Round four"). A child is
// entered when any lane enters its box; of two, the one more lanes enter
// first is walked first. Each lane keeps its own closest hit and its own
// entry distance for every pushed node, so a node is popped only while some
// lane can still find a nearer hit in it. Lanes test triangles in leaves
// their ray may not enter: a hit there is a real hit before the lane's
// limit, so the closest hit is the same as the lane's own walk finds (of
// hits at exactly one t, the first found wins in either walk).
bool traverseMeshPacket(Ray worldRay, uint index, bool anyHit, float tMax, inout HitId best)
{
    const float notEntered = uintBitsToFloat(0x7f800000u); // +inf: beyond every limit
    Mesh mesh = meshes[index];
    Ray r = rayToObject(mesh, worldRay);
    TriangleRay tr = triangleRaySetup(r);
    BvhRay br = bvhRaySetup(r);
    uint root = subgroupBroadcastFirst(mesh.root);
    uint firstTriangle = subgroupBroadcastFirst(mesh.firstTriangle);
    uint stackNode[BVH_STACK_SIZE]; // subgroup-uniform
    float stackEntry[BVH_STACK_SIZE]; // this lane's entry into the pushed node
    uint depth = 0u;
    uint node = 0u;
    float tEntry;
    BvhNode rootNode = meshNodes[root];
    bool done = false; // anyHit: this lane has its answer
    bool found = false;
    bool visiting = subgroupAny(entersBox(rootNode.lower, rootNode.upper, br, anyHit ? tMax : best.t, tEntry));
    while (visiting) {
        ++g_loopIterations;
        node = subgroupBroadcastFirst(node);
        BvhNode n = meshNodes[root + node];
        float limit = anyHit ? tMax : best.t;
        bool descend = false;
        if (n.count > 0u) {
            for (uint k = 0u; k < n.count; ++k) {
                ++g_loopIterations;
                uint slot = n.first + k;
                MeshTriangle tri = meshTriangles[firstTriangle + slot];
                float t;
                vec3 bary;
                if (!done && intersectTriangle(tri.v0, tri.v1, tri.v2, r, tr, limit, t, bary)) {
#ifdef VKRT_HAS_ALPHA
                    if (!alphaKeeps(worldRay, index, mesh, slot, bary))
                        continue;
#endif
                    found = true;
                    if (anyHit) {
                        done = true;
                    } else {
                        best = HitId(SHAPE_MESH, index, t, bary, true, slot);
                        limit = t;
                    }
                }
            }
            if (anyHit && subgroupAll(done))
                return found;
        } else {
            uint first = n.first;
            BvhNode a = meshNodes[root + first];
            BvhNode b = meshNodes[root + first + 1u];
            float ta, tb;
            bool ha = !done && entersBox(a.lower, a.upper, br, limit, ta);
            bool hb = !done && entersBox(b.lower, b.upper, br, limit, tb);
            // One cross-lane sum for the four counts (each fits 8 bits): lavapipe
            // builds every subgroup operation as a loop over the lanes, and
            // one sum instead of two votes and two ballots was 1.11x on camera rays.
            uint votes = subgroupAdd((ha ? 1u : 0u) | (hb ? 0x100u : 0u) | (ha && (!hb || ta <= tb) ? 0x10000u : 0u) |
                                     (hb && (!ha || tb < ta) ? 0x1000000u : 0u));
            bool anyA = (votes & 0xffu) != 0u, anyB = (votes & 0xff00u) != 0u;
            uint aFirstVotes = (votes >> 16) & 0xffu, bFirstVotes = votes >> 24;
            if (anyA && anyB) {
                bool aNear = aFirstVotes >= bFirstVotes;
                stackNode[depth] = aNear ? first + 1u : first;
                stackEntry[depth] = aNear ? (hb ? tb : notEntered) : (ha ? ta : notEntered);
                ++depth;
                node = aNear ? first : first + 1u;
                descend = true;
            } else if (anyA || anyB) {
                node = anyA ? first : first + 1u;
                descend = true;
            }
        }
        if (!descend) {
            visiting = false;
            while (depth > 0u) {
                ++g_loopIterations;
                --depth;
                if (subgroupAny(!done && stackEntry[depth] <= (anyHit ? tMax : best.t))) {
                    node = stackNode[depth];
                    visiting = true;
                    break;
                }
            }
        }
    }
    return found;
}

// Whether the active lanes walk this instance as one packet: they all are
// in it and their rays point into one octant (camera rays of a pixel block,
// shadow rays to one light; not the scattered directions of diffuse bounces).
bool meshPacketPays(Ray worldRay, uint index)
{
    uint octant = (worldRay.dir.x < 0.0 ? 1u : 0u) | (worldRay.dir.y < 0.0 ? 2u : 0u) | (worldRay.dir.z < 0.0 ? 4u : 0u);
    return subgroupAllEqual(index) && subgroupAllEqual(octant);
}
#endif

// The closest (anyHit: any) triangle of mesh instance `index` before best.t
// (tMax) that its alpha test keeps (lib/alpha.glsl). Returns whether one was found.
bool traverseMesh(Ray worldRay, uint index, bool anyHit, float tMax, inout HitId best)
{
#ifdef VKRT_PACKET_TRAVERSAL
    if (meshPacketPays(worldRay, index))
        return traverseMeshPacket(worldRay, index, anyHit, tMax, best);
#endif
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
// lavapipe inlines every call, so that never-taken loop would cost two more
// copies of the mesh walk (closest and any hit) in every mesh kernel's
// compile (docs/performance.md has the figures).
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
