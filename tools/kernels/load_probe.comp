#version 460
// What a node load costs on the device: each invocation follows a chain of
// `steps` BVH-sized nodes (two vec4: lower box + link, upper box + count),
// the next node's index read from the one just loaded, as a BVH walk does.
// Built three ways (tools/load_probe.cpp):
//   LOAD_MODE 0  per lane: the index is the lane's own (a gather per lane,
//                whether or not the lanes happen to agree at run time);
//   LOAD_MODE 1  subgroup-uniform: the index goes through
//                subgroupBroadcastFirst, so the compiler knows every lane
//                loads the same node (what a packet walk's loads are);
//   LOAD_MODE 2  one lane loads (subgroupElect) and broadcasts the node,
//                for a compiler that does not know uniform loads;
//   LOAD_MODE 3  as 1, plus the one cross-lane sum per node a packet walk
//                needs to decide which children to enter;
//   LOAD_MODE 4  as 0, but through the buffer's device address
//                (GL_EXT_buffer_reference): llvmpipe gathers such a load,
//                where it loops over the lanes for a storage buffer's.
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#if LOAD_MODE == 4
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodeArray { vec4 v[]; };
#endif

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Nodes { vec4 nodes[]; };
layout(std430, binding = 1) readonly buffer Starts { uint starts[]; };
layout(std430, binding = 2) writeonly buffer Sums { float sums[]; };
layout(push_constant) uniform Push { uint steps; uint nodeCount; uvec2 nodesAddress; };

uint chainIndex(uint index)
{
#if LOAD_MODE >= 1
    return subgroupBroadcastFirst(index);
#else
    return index;
#endif
}

void main()
{
    uint id = gl_GlobalInvocationID.x;
    uint node = chainIndex(starts[id]);
    // A slab test's worth of arithmetic per node, so the loads are not all there is.
    vec3 origin = vec3(float(id & 7u), float((id >> 3) & 7u), 0.5) * 0.01;
    vec3 invDir = vec3(1.0, 2.0, 3.0);
    float sum = 0.0;
    for (uint i = 0u; i < steps; ++i) {
#if LOAD_MODE == 2
        vec4 lower = vec4(0.0), upper = vec4(0.0);
        if (subgroupElect()) {
            lower = nodes[2u * node];
            upper = nodes[2u * node + 1u];
        }
        lower = subgroupBroadcastFirst(lower);
        upper = subgroupBroadcastFirst(upper);
#elif LOAD_MODE == 4
        vec4 lower = NodeArray(nodesAddress).v[2u * node];
        vec4 upper = NodeArray(nodesAddress).v[2u * node + 1u];
#else
        vec4 lower = nodes[2u * node];
        vec4 upper = nodes[2u * node + 1u];
#endif
        vec3 t0 = (lower.xyz - origin) * invDir;
        vec3 t1 = (upper.xyz - origin) * invDir;
        vec3 tNear = min(t0, t1);
        vec3 tFar = max(t0, t1);
        float entry = max(max(tNear.x, tNear.y), tNear.z);
        float exit = min(min(tFar.x, tFar.y), tFar.z);
        sum += entry <= exit ? entry : upper.w;
#if LOAD_MODE == 3
        // A packet walk's vote per node: one subgroup sum of packed counts.
        uint votes = subgroupAdd((entry <= exit ? 1u : 0u) | (entry < 0.5 ? 0x100u : 0u));
        sum += float(votes & 0xffu);
#endif
        node = chainIndex(floatBitsToUint(lower.w) % nodeCount);
    }
    sums[id] = sum;
}
