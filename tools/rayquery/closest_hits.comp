// vkrt-rayquery-bench's kernel: per pixel, `spp` jittered camera rays through
// the device's own acceleration structure (VK_KHR_ray_query), each to its
// closest triangle; counts the hits and sums their distances.
#version 460
#extension GL_EXT_ray_query : require
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform accelerationStructureEXT scene;
struct PixelResult {
    uint hits;
    float distanceSum;
};
layout(scalar, binding = 1) buffer ResultBlock { PixelResult result[]; };
layout(push_constant, scalar) uniform Camera {
    vec3 eye;
    uint width;
    vec3 right; // scaled by tan(fov / 2) * aspect
    uint height;
    vec3 up;    // scaled by tan(fov / 2)
    uint spp;
    vec3 forward;
} camera;

uint hash(uint x)
{
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

void main()
{
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= camera.width || pixel.y >= camera.height)
        return;
    uint index = pixel.y * camera.width + pixel.x;
    uint hits = 0u;
    float distanceSum = 0.0;
    for (uint s = 0u; s < camera.spp; ++s) {
        uint h = hash(index * 9781u + s * 6271u + 1u);
        vec2 jitter = vec2(h & 0xffffu, h >> 16u) / 65536.0;
        vec2 film = (vec2(pixel) + jitter) / vec2(camera.width, camera.height);
        vec2 ndc = vec2(2.0 * film.x - 1.0, 1.0 - 2.0 * film.y);
        vec3 dir = normalize(ndc.x * camera.right + ndc.y * camera.up + camera.forward);
        rayQueryEXT query;
        rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT, 0xffu, camera.eye, 0.0, dir, 1e30);
        while (rayQueryProceedEXT(query)) {
        }
        if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
            ++hits;
            distanceSum += rayQueryGetIntersectionTEXT(query, true);
        }
    }
    result[index].hits = hits;
    result[index].distanceSum = distanceSum;
}
