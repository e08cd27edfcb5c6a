// The path integrator in two stages (render --staged): a trace stage finds
// what each lane's pending rays hit, a shade stage does everything else
// (emission, next-event estimation, BSDF sampling, accumulation). Each stage
// is a kernel of its own, so the driver compiles two smaller functions
// instead of one that holds both: lavapipe inlines every call, and its
// compile time grows far faster than linearly with the inlined size
// (docs/performance.md, "Staged kernels").
//
// A lane's path lives in the lane buffer between dispatches. The host
// alternates shade and trace dispatches until no lane has work left. The
// arithmetic and its order are the megakernel's (lib/path.glsl:
// advancePath): the trace stage traces a vertex's shadow ray, then the next
// segment, and the shade stage adds the shadow ray's light before anything
// the segment finds, so images are the same bit for bit.
#ifndef VKRT_STAGES_GLSL
#define VKRT_STAGES_GLSL

const uint LANE_IDLE = 0u;    // cleared: starts the current run at the next shade
const uint LANE_TRACE = 1u;   // a segment (and maybe a shadow ray) to trace
const uint LANE_SHADOW = 2u;  // the path has ended; its last shadow ray to trace
const uint LANE_DONE = 3u;    // every frame of the run added

// What a lane keeps between dispatches: STAGED_LANE_VEC4S words of 16
// bytes (shared/Bindings.h). lavapipe turns every buffer access whose
// address differs between lanes into a loop over the 8 lanes, so the state
// moves as whole vec4s: one access per member made the shade stage compile
// and run slower (docs/performance.md, "Staged kernels").
//   0 phase, runFirst, runEnd, frameIndex    9  shadow dir, pending
//   1 rng dimension, loop counts (3)        10  shadow weight, -
//   2 radiance, bsdfPdf                     11  shadow light, -
//   3 throughput, cosinePdf                 12  shadow absorption, -
//   4 media interiors                       13  hit shape, index, t, primitive
//   5 media count, refracted indices, specular  14 hit detail, found | front | shadow blocked
//   6 ray origin, depth                     15-17 AOVs (albedo, depth; normal, hit; position, settled)
//   7 ray dir, pathLength
//   8 shadow origin, dist
layout(scalar, binding = BINDING_STAGED_LANES) buffer StagedLaneBlock {
    uvec4 laneHeader; // x: set to 1 by every shade that leaves a lane work; the host clears it
    uvec4 laneWords[];
};

uint laneBase(uint slot) { return slot * STAGED_LANE_VEC4S; }
vec4 laneVec(uint slot, uint k) { return uintBitsToFloat(laneWords[laneBase(slot) + k]); }
void setLaneVec(uint slot, uint k, vec3 v, float w) { laneWords[laneBase(slot) + k] = floatBitsToUint(vec4(v, w)); }
void setLaneVec(uint slot, uint k, vec3 v, uint w) { laneWords[laneBase(slot) + k] = uvec4(floatBitsToUint(v), w); }

const uint FOUND_HIT = 1u;
const uint FRONT_HIT = 2u;
const uint SHADOW_BLOCKED = 4u;

PathTracer loadPath(uint slot)
{
    PathTracer p;
    vec4 v2 = laneVec(slot, 2u), v3 = laneVec(slot, 3u), v6 = laneVec(slot, 6u), v7 = laneVec(slot, 7u);
    uvec4 v5 = laneWords[laneBase(slot) + 5u];
    p.path.radiance = v2.xyz;
    p.path.bsdfPdf = v2.w;
    p.path.throughput = v3.xyz;
    p.path.cosinePdf = v3.w;
    p.path.media.interiors = laneWords[laneBase(slot) + 4u];
    p.path.media.count = v5.x;
    p.path.media.refractedIndices = uintBitsToFloat(v5.yz);
    p.path.specular = v5.w != 0u;
    p.ray = Ray(v6.xyz, v7.xyz);
    p.depth = floatBitsToUint(v6.w);
#ifdef VKRT_HAS_TEXTURES
    p.pathLength = v7.w;
#endif
    return p;
}

void storePath(uint slot, PathTracer p)
{
    setLaneVec(slot, 2u, p.path.radiance, p.path.bsdfPdf);
    setLaneVec(slot, 3u, p.path.throughput, p.path.cosinePdf);
    laneWords[laneBase(slot) + 4u] = p.path.media.interiors;
    laneWords[laneBase(slot) + 5u] = uvec4(p.path.media.count, floatBitsToUint(p.path.media.refractedIndices),
                                           p.path.specular ? 1u : 0u);
    setLaneVec(slot, 6u, p.ray.origin, p.depth);
#ifdef VKRT_HAS_TEXTURES
    setLaneVec(slot, 7u, p.ray.dir, p.pathLength);
#else
    setLaneVec(slot, 7u, p.ray.dir, 0.0);
#endif
}

ShadowTest loadShadow(uint slot)
{
    vec4 v8 = laneVec(slot, 8u), v9 = laneVec(slot, 9u);
    ShadowTest t;
    t.pending = floatBitsToUint(v9.w) != 0u;
    t.ray = Ray(v8.xyz, v9.xyz);
    t.dist = v8.w;
    t.weight = laneVec(slot, 10u).xyz;
    t.light = laneVec(slot, 11u).xyz;
    t.absorption = laneVec(slot, 12u).xyz;
    return t;
}

void storeShadow(uint slot, ShadowTest t)
{
    setLaneVec(slot, 8u, t.ray.origin, t.dist);
    setLaneVec(slot, 9u, t.ray.dir, t.pending ? 1u : 0u);
    setLaneVec(slot, 10u, t.weight, 0u);
    setLaneVec(slot, 11u, t.light, 0u);
    setLaneVec(slot, 12u, t.absorption, 0u);
}

#ifdef VKRT_AOV
void loadAov(uint slot)
{
    vec4 a = laneVec(slot, 15u), b = laneVec(slot, 16u), c = laneVec(slot, 17u);
    g_aov = AovSample(a.xyz, b.xyz, c.xyz, a.w, floatBitsToUint(b.w) != 0u, floatBitsToUint(c.w) != 0u);
}

void storeAov(uint slot)
{
    setLaneVec(slot, 15u, g_aov.albedo, g_aov.depth);
    setLaneVec(slot, 16u, g_aov.normal, g_aov.hit ? 1u : 0u);
    setLaneVec(slot, 17u, g_aov.position, g_aov.settled ? 1u : 0u);
}
#endif

// ---- trace stage ----

// Traces the lane's pending shadow ray, then its next segment, from one call
// site (a loop of one or two passes: one inlined copy of the BVH walk).
void traceStage(uint pixelIndex, uint slot)
{
    uvec4 v0 = laneWords[laneBase(slot)];
    uint phase = v0.x;
    if (phase != LANE_TRACE && phase != LANE_SHADOW)
        return;
    uvec4 v1 = laneWords[laneBase(slot) + 1u];
    g_loopIterations = v1.y;
#ifdef VKRT_HAS_ALPHA
    alphaStartSample(pixelIndex, v0.w, frame.seed);
#endif
    vec4 v8 = laneVec(slot, 8u), v9 = laneVec(slot, 9u);
    bool shadowPending = floatBitsToUint(v9.w) != 0u;
    uint flags = 0u;
    HitId id = noHit(FLT_MAX);
    for (uint pass = shadowPending ? 0u : 1u; pass < (phase == LANE_TRACE ? 2u : 1u); ++pass) {
        bool shadowPass = pass == 0u;
        Ray ray = shadowPass ? Ray(v8.xyz, v9.xyz) : Ray(laneVec(slot, 6u).xyz, laneVec(slot, 7u).xyz);
        HitId found;
        if (findHit(ray, shadowPass ? v8.w : FLT_MAX, shadowPass, found))
            flags |= shadowPass ? SHADOW_BLOCKED : FOUND_HIT;
        if (!shadowPass)
            id = found;
    }
    if (id.front)
        flags |= FRONT_HIT;
    laneWords[laneBase(slot) + 13u] = uvec4(uint(id.shape), id.index, floatBitsToUint(id.t), id.primitive);
    setLaneVec(slot, 14u, id.detail, flags);
    v1.y = g_loopIterations;
    laneWords[laneBase(slot) + 1u] = v1;
}

// ---- shade stage ----

// The shade stage's view of a lane: its path, shadow ray and sampler.
struct ShadeState {
    uint phase;
    uint frameIndex;
    uint runEnd;
    Sampler rng;
    PathTracer path;
    ShadowTest shadow;
};

// Shades what the trace stage found (or starts the run), leaving the lane
// a segment to trace, its last shadow ray, or done. Every step is called
// from one site (a driver that inlines every call compiles each once).
void shadeLane(inout ShadeState lane, uvec2 pixel, uint pixelIndex, uint slot)
{
    bool finish = false;
    bool start = false;
    if (lane.phase == LANE_IDLE || lane.phase == LANE_DONE) {
        // The run's first shade: its first frame's camera ray.
        lane.frameIndex = frame.firstFrame;
        lane.runEnd = run.frameEnd;
        g_loopIterations = 0u;
        g_longestSample = 0u;
        g_sampleStart = 0u;
        start = lane.frameIndex < lane.runEnd;
        lane.phase = LANE_DONE;
    } else {
#ifdef VKRT_HAS_ALPHA
        alphaStartSample(pixelIndex, lane.frameIndex, frame.seed);
#endif
        if (lane.shadow.pending)
            addShadowedLight(lane.path, lane.shadow, (laneWords[laneBase(slot) + 14u].w & SHADOW_BLOCKED) != 0u);
        lane.shadow.pending = false;
        if (lane.phase == LANE_SHADOW) {
            finish = true;
        } else {
            SurfaceHit hit;
            uvec4 v13 = laneWords[laneBase(slot) + 13u], v14 = laneWords[laneBase(slot) + 14u];
            bool found = (v14.w & FOUND_HIT) != 0u;
            if (found)
                hit = describeHit(lane.path.ray, HitId(int(v13.x), v13.y, uintBitsToFloat(v13.z),
                                                       uintBitsToFloat(v14.xyz), (v14.w & FRONT_HIT) != 0u, v13.w));
            if (scatterAtHit(lane.path, found, hit, lane.rng, lane.shadow))
                ++g_loopIterations;
            else if (lane.shadow.pending)
                lane.phase = LANE_SHADOW;
            else
                finish = true;
        }
    }
    if (finish) {
        // The finished sample joins the pixel's sums; the next frame's starts.
        AccumPixel sum = accum[slot];
        Sampler rng = lane.rng;
        start = finishSample(sum, pixelIndex, slot, lane.frameIndex, lane.runEnd, lane.path.path.radiance, rng);
        accum[slot] = sum;
        if (!start) {
            lane.phase = LANE_DONE;
            reportLoopIterations(g_longestSample);
        }
    }
    if (start) {
        lane.rng = samplerCreate(pixelIndex, lane.frameIndex, frame.seed);
        aovStartSample();
        lane.path = startPath(cameraSample(pixel, lane.rng));
        lane.shadow.pending = false;
        lane.phase = LANE_TRACE;
        ++g_loopIterations; // advancePath's count: one per segment
    }
}

void shadeStage(uvec2 pixel, uint pixelIndex, uint slot)
{
    // A lane done with this run reads one word, not its whole path.
    uvec4 v0 = laneWords[laneBase(slot)];
    if (v0.x == LANE_DONE && v0.y == frame.firstFrame && v0.z == run.frameEnd)
        return;
    uvec4 v1 = laneWords[laneBase(slot) + 1u];
    ShadeState lane;
    lane.phase = v0.x;
    lane.frameIndex = v0.w;
    lane.runEnd = v0.z;
    lane.rng = samplerCreate(pixelIndex, lane.frameIndex, frame.seed);
    lane.rng.dimension = v1.x;
    if (lane.phase == LANE_TRACE || lane.phase == LANE_SHADOW) {
        lane.path = loadPath(slot);
        lane.shadow = loadShadow(slot);
        g_loopIterations = v1.y;
        g_longestSample = v1.z;
        g_sampleStart = v1.w;
#ifdef VKRT_AOV
        loadAov(slot);
#endif
    }
    shadeLane(lane, pixel, pixelIndex, slot);
    laneWords[laneBase(slot)] = uvec4(lane.phase, frame.firstFrame, lane.runEnd, lane.frameIndex);
    laneWords[laneBase(slot) + 1u] = uvec4(lane.rng.dimension, g_loopIterations, g_longestSample, g_sampleStart);
    if (lane.phase == LANE_DONE)
        return;
    storePath(slot, lane.path);
    if (lane.shadow.pending)
        storeShadow(slot, lane.shadow);
    else
        laneWords[laneBase(slot) + 9u].w = 0u;
#ifdef VKRT_AOV
    storeAov(slot);
#endif
    laneHeader.x = 1u;
}

#endif
