// One dispatch adds one or more samples per pixel to the accumulation buffer.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_control_flow_attributes : require
#ifdef VKRT_ACCEL_DRIVER
#extension GL_EXT_ray_query : require
#endif
#ifdef VKRT_GROUP_LOOP_COUNT
#extension GL_KHR_shader_subgroup_arithmetic : require
#endif
#ifdef VKRT_PACKET_TRAVERSAL
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#endif
#ifdef VKRT_TEXTURE_CHUNKS
#extension GL_EXT_nonuniform_qualifier : require
#endif
// The scene's read-only buffers read through their device addresses
// (lib/scene_buffers.glsl), where the device has them.
#ifdef VKRT_SCENE_ADDRESSES
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_buffer_reference_uvec2 : require
#endif

#include "lib/bindings.glsl"

layout(local_size_x = WORKGROUP_SIZE_X, local_size_y = WORKGROUP_SIZE_Y) in;

#include "lib/random.glsl"
#include "lib/ray.glsl"
#include "lib/camera.glsl"
#include "lib/intersect.glsl"
#include "lib/bvh.glsl"
#include "lib/scene.glsl"
#include "lib/accumulate.glsl"
#include "lib/fresnel.glsl"
#include "lib/sampling.glsl"
#include "lib/microfacet.glsl"
#include "lib/bsdf.glsl"
#ifdef VKRT_HAS_TEXTURES
#include "lib/material_textures.glsl"
#endif
#include "lib/environment.glsl"
#include "lib/media.glsl"
#include "lib/lights.glsl"
#include "lib/aov.glsl"
#ifdef VKRT_INTEGRATOR_PATH
#include "lib/path.glsl"
#else
#include "lib/whitted.glsl"
#endif

// An image whose per-pixel buffers would exceed one storage buffer's range
// is rendered in bands of whole workgroup rows (render/ImageBands.h), each
// with its own buffers: band b's dispatch has base workgroup y = b *
// gl_NumWorkGroups.y. The first workgroup row of the invocation's band:
uint bandFirstTileRow()
{
    return gl_WorkGroupID.y - gl_WorkGroupID.y % gl_NumWorkGroups.y;
}

// lavapipe hands each worker thread one contiguous run of workgroups; walking
// the band's tiles (u.tileCount of them) with a stride coprime to their count
// gives every thread a share of every part of it, so no core idles on the
// cheap sky.
uvec2 scatteredPixel()
{
    uint tilesX = (u.width + WORKGROUP_SIZE_X - 1u) / WORKGROUP_SIZE_X;
    uint group = (gl_WorkGroupID.y % gl_NumWorkGroups.y) * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint tile = (group * u.tileStride) % u.tileCount;
    uvec2 tileInImage = uvec2(tile % tilesX, tile / tilesX + bandFirstTileRow());
    return tileInImage * uvec2(WORKGROUP_SIZE_X, WORKGROUP_SIZE_Y) + gl_LocalInvocationID.xy;
}

// A capping driver counts the loop passes of a whole subgroup, and a pass
// runs while any lane needs it: the lanes' sum bounds the group's count.
// maxLoopIterations reports the longest single sample.
void reportLoopIterations(uint longestSample)
{
#ifdef VKRT_GROUP_LOOP_COUNT
    uint count = subgroupAdd(g_loopIterations);
#else
    uint count = g_loopIterations;
#endif
    atomicMax(stats.maxLoopIterations, longestSample);
    if (count >= LOOP_BUDGET)
        atomicAdd(stats.budgetExceeded, 1u);
}

Ray cameraSample(uvec2 pixel, inout Sampler rng)
{
#ifdef VKRT_THIN_LENS
    // One 4-D sample: the point in the pixel and the point on the lens. (A
    // pinhole scene in the uber kernel takes the pinhole's path below: the
    // same rays and random numbers, so the same image bit for bit.)
    if (u.apertureRadius > 0.0) {
        vec4 s = sampleNext4D(rng);
        vec2 subpixel = (u.flags & RENDER_FLAG_JITTER) != 0u ? s.xy : vec2(0.5);
        return thinLensRay(pixel, subpixel, s.zw);
    }
#endif
    vec2 subpixel = (u.flags & RENDER_FLAG_JITTER) != 0u ? sampleNext2D(rng) : vec2(0.5);
    return cameraRay(pixel, subpixel);
}

// Measurement hook (path integrator): a sample's radiance becomes the number
// of path segments it traced, for tools/lane_occupancy.py.
uint g_segmentsOfSample = 0u;

// The test and measurement hooks replace a finished sample's radiance.
vec3 testedSample(vec3 radiance, uint pixelIndex, uint frameIndex)
{
#ifdef VKRT_MEASURE_SEGMENTS
    radiance = vec3(float(g_segmentsOfSample));
    g_segmentsOfSample = 0u;
#endif
#ifdef VKRT_TEST_ALTERNATING_SAMPLES
    // Test hook: samples alternate between OFFSET and OFFSET + 1 frame by frame.
    radiance = vec3(VKRT_TEST_ALTERNATING_SAMPLES + float(frameIndex & 1u));
#endif
#ifdef VKRT_TEST_OUTLIER_SAMPLES
    // Test hook: the constant VKRT_TEST_OUTLIER_SAMPLES, except that one
    // (pixel, frame) in 10,000 carries an outlier a million times larger.
    radiance = vec3(VKRT_TEST_OUTLIER_SAMPLES);
    if ((pixelIndex * 7919u + frameIndex) % 10000u == 0u)
        radiance *= 1e6;
#endif
#ifdef VKRT_TEST_INJECT_NONFINITE
    // Test hook: poison every 7th pixel so the rejection path is exercised.
    if (pixelIndex % 7u == 0u)
        radiance = vec3(uintBitsToFloat(0x7fc00000u));
#endif
    return radiance;
}

// The loop passes of the longest sample so far, and where the current one began.
uint g_longestSample = 0u;
uint g_sampleStart = 0u;

// Adds frame frameIndex's finished sample to `sum` (the pixel's record
// `slot` of its band) and moves to the next frame, with its sampler; false
// after the invocation's last frame.
bool finishSample(inout AccumPixel sum, uint pixelIndex, uint slot, inout uint frameIndex, uint frameEnd,
                  vec3 radiance, inout Sampler rng)
{
#ifdef VKRT_AOV
    uint accepted = sum.count;
#endif
    accumulateSample(sum, slot, frameIndex, testedSample(radiance, pixelIndex, frameIndex));
#ifdef VKRT_AOV
    if (sum.count != accepted)
        accumulateAov(slot, sum.count); // the sample's AOVs count where its radiance does
#endif
    g_longestSample = max(g_longestSample, g_loopIterations - g_sampleStart);
    g_sampleStart = g_loopIterations;
    if (++frameIndex == frameEnd)
        return false;
    rng = samplerCreate(pixelIndex, frameIndex, frame.seed);
    aovStartSample();
#ifdef VKRT_HAS_ALPHA
    alphaStartSample(pixelIndex, frameIndex, frame.seed);
#endif
    return true;
}

#ifdef VKRT_STAGE
#include "lib/stages.glsl"

// A staged kernel (VKRT_STAGE 1: trace, 2: shade) works on its pixel's lane.
void main()
{
    uvec2 pixel = scatteredPixel();
    if (pixel.x >= u.width || pixel.y >= u.height)
        return;
    uint pixelIndex = pixel.y * u.width + pixel.x;
    uint slot = pixelIndex - bandFirstTileRow() * WORKGROUP_SIZE_Y * u.width;
#if VKRT_STAGE == 1
    traceStage(pixelIndex, slot);
#else
    shadeStage(pixel, pixelIndex, slot);
#endif
}
#else
// One invocation adds frames [frameIndex, frameEnd) of its pixel (FrameRun),
// in order, so the sums are the same as one frame per dispatch would give.
void main()
{
    uvec2 pixel = scatteredPixel();
    if (pixel.x >= u.width || pixel.y >= u.height)
        return;
    uint pixelIndex = pixel.y * u.width + pixel.x; // the image's: seeds the sampler
    uint slot = pixelIndex - bandFirstTileRow() * WORKGROUP_SIZE_Y * u.width; // its band's buffers'
    uint frameIndex = frame.firstFrame + gl_WorkGroupID.z * run.framesPerInvocation; // shared/SceneTypes.h
    uint frameEnd = min(frameIndex + run.framesPerInvocation, run.frameEnd);
    if (frameIndex >= frameEnd)
        return;
    AccumPixel sum = accum[slot];
    Sampler rng = samplerCreate(pixelIndex, frameIndex, frame.seed);
    aovStartSample();
#ifdef VKRT_HAS_ALPHA
    alphaStartSample(pixelIndex, frameIndex, frame.seed);
#endif
#ifdef VKRT_INTEGRATOR_PATH
    // Path regeneration (Novak et al. 2010): 8 lanes run in lockstep, so a
    // lane whose path has ended starts its next sample at once instead of
    // idling until the group's longest path ends.
    PathTracer path = startPath(cameraSample(pixel, rng));
    for (;;) {
#ifdef VKRT_MEASURE_SEGMENTS
        ++g_segmentsOfSample;
#endif
        if (advancePath(path, rng))
            continue;
        if (!finishSample(sum, pixelIndex, slot, frameIndex, frameEnd, path.path.radiance, rng))
            break;
        path = startPath(cameraSample(pixel, rng));
    }
#else
    for (;;) {
        vec3 radiance = traceWhitted(cameraSample(pixel, rng), rng);
        if (!finishSample(sum, pixelIndex, slot, frameIndex, frameEnd, radiance, rng))
            break;
    }
#endif
    accum[slot] = sum;
    reportLoopIterations(g_longestSample);
}
#endif
