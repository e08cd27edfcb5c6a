// The path integrator in two stages (render --staged): a trace stage finds
// what each lane's pending rays hit, a shade stage does everything else
// (emission, next-event estimation, BSDF sampling, accumulation). Each stage
// is a kernel of its own, so the driver compiles two smaller functions
// instead of one that holds both: lavapipe inlines every call, and its
// compile time grows far faster than linearly with the inlined size
// (docs/performance.md, "Staged kernels").
//
// A lane's path lives in `lanes[slot]` between dispatches. The host
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

// What a lane keeps between dispatches, in plain members only: a struct
// copied whole between a buffer and a variable (bools, nested structs) is
// not valid SPIR-V from glslang, so each member is copied by itself below.
struct StagedLane {
    uint phase;
    uint runFirst;  // the run it works on (FrameConstants::firstFrame, FrameRun::frameEnd)
    uint runEnd;
    uint frameIndex;
    uint rngDimension;
    // PathTracer
    vec3 radiance;
    vec3 throughput;
    uint mediaCount;
    uvec4 mediaMaterials;
    vec2 mediaRefractedIndices;
    uint specular;
    float bsdfPdf;
    float cosinePdf;
    vec3 rayOrigin;
    vec3 rayDir;
    uint depth;
    float pathLength;
    // ShadowTest
    uint shadowPending;
    vec3 shadowOrigin;
    vec3 shadowDir;
    float shadowDist;
    vec3 shadowWeight;
    vec3 shadowLight;
    vec3 shadowAbsorption;
    // the trace stage's answers: HitId for the segment, and the shadow ray's
    int hitShape;
    uint hitIndex;
    float hitT;
    vec3 hitDetail;
    uint hitFront;
    uint hitPrimitive;
    uint found;
    uint shadowBlocked;
    // loop counts (render.comp: reportLoopIterations)
    uint loopIterations;
    uint longestSample;
    uint sampleStart;
#ifdef VKRT_AOV
    vec3 aovAlbedo;
    vec3 aovNormal;
    vec3 aovPosition;
    float aovDepth;
    uint aovHit;
    uint aovSettled;
#endif
};

layout(scalar, binding = BINDING_STAGED_LANES) buffer StagedLaneBlock {
    uint lanesWithWork; // set (to 1) by every shade that leaves a lane work; the host clears it
    uint unusedWords[3];
    StagedLane lanes[];
};

PathTracer loadPath(uint slot)
{
    PathTracer p;
    p.path.radiance = lanes[slot].radiance;
    p.path.throughput = lanes[slot].throughput;
    p.path.media.count = lanes[slot].mediaCount;
    p.path.media.materials = lanes[slot].mediaMaterials;
    p.path.media.refractedIndices = lanes[slot].mediaRefractedIndices;
    p.path.specular = lanes[slot].specular != 0u;
    p.path.bsdfPdf = lanes[slot].bsdfPdf;
    p.path.cosinePdf = lanes[slot].cosinePdf;
    p.ray.origin = lanes[slot].rayOrigin;
    p.ray.dir = lanes[slot].rayDir;
    p.depth = lanes[slot].depth;
#ifdef VKRT_HAS_TEXTURES
    p.pathLength = lanes[slot].pathLength;
#endif
    return p;
}

void storePath(uint slot, PathTracer p)
{
    lanes[slot].radiance = p.path.radiance;
    lanes[slot].throughput = p.path.throughput;
    lanes[slot].mediaCount = p.path.media.count;
    lanes[slot].mediaMaterials = p.path.media.materials;
    lanes[slot].mediaRefractedIndices = p.path.media.refractedIndices;
    lanes[slot].specular = p.path.specular ? 1u : 0u;
    lanes[slot].bsdfPdf = p.path.bsdfPdf;
    lanes[slot].cosinePdf = p.path.cosinePdf;
    lanes[slot].rayOrigin = p.ray.origin;
    lanes[slot].rayDir = p.ray.dir;
    lanes[slot].depth = p.depth;
#ifdef VKRT_HAS_TEXTURES
    lanes[slot].pathLength = p.pathLength;
#endif
}

ShadowTest loadShadow(uint slot)
{
    ShadowTest t;
    t.pending = lanes[slot].shadowPending != 0u;
    t.ray = Ray(lanes[slot].shadowOrigin, lanes[slot].shadowDir);
    t.dist = lanes[slot].shadowDist;
    t.weight = lanes[slot].shadowWeight;
    t.light = lanes[slot].shadowLight;
    t.absorption = lanes[slot].shadowAbsorption;
    return t;
}

void storeShadow(uint slot, ShadowTest t)
{
    lanes[slot].shadowPending = t.pending ? 1u : 0u;
    if (!t.pending)
        return;
    lanes[slot].shadowOrigin = t.ray.origin;
    lanes[slot].shadowDir = t.ray.dir;
    lanes[slot].shadowDist = t.dist;
    lanes[slot].shadowWeight = t.weight;
    lanes[slot].shadowLight = t.light;
    lanes[slot].shadowAbsorption = t.absorption;
}

HitId loadHit(uint slot)
{
    return HitId(lanes[slot].hitShape, lanes[slot].hitIndex, lanes[slot].hitT, lanes[slot].hitDetail,
                 lanes[slot].hitFront != 0u, lanes[slot].hitPrimitive);
}

void storeHit(uint slot, HitId id)
{
    lanes[slot].hitShape = id.shape;
    lanes[slot].hitIndex = id.index;
    lanes[slot].hitT = id.t;
    lanes[slot].hitDetail = id.detail;
    lanes[slot].hitFront = id.front ? 1u : 0u;
    lanes[slot].hitPrimitive = id.primitive;
}

#ifdef VKRT_AOV
void loadAov(uint slot)
{
    g_aov = AovSample(lanes[slot].aovAlbedo, lanes[slot].aovNormal, lanes[slot].aovPosition, lanes[slot].aovDepth,
                      lanes[slot].aovHit != 0u, lanes[slot].aovSettled != 0u);
}

void storeAov(uint slot)
{
    lanes[slot].aovAlbedo = g_aov.albedo;
    lanes[slot].aovNormal = g_aov.normal;
    lanes[slot].aovPosition = g_aov.position;
    lanes[slot].aovDepth = g_aov.depth;
    lanes[slot].aovHit = g_aov.hit ? 1u : 0u;
    lanes[slot].aovSettled = g_aov.settled ? 1u : 0u;
}
#endif

// ---- trace stage ----

// Traces the lane's pending shadow ray, then its next segment, from one call
// site (a loop of one or two passes: one inlined copy of the BVH walk).
void traceStage(uint pixelIndex, uint slot)
{
    uint phase = lanes[slot].phase;
    if (phase != LANE_TRACE && phase != LANE_SHADOW)
        return;
    g_loopIterations = lanes[slot].loopIterations;
#ifdef VKRT_HAS_ALPHA
    alphaStartSample(pixelIndex, lanes[slot].frameIndex, frame.seed);
#endif
    bool shadowPending = lanes[slot].shadowPending != 0u;
    for (uint pass = shadowPending ? 0u : 1u; pass < (phase == LANE_TRACE ? 2u : 1u); ++pass) {
        bool shadowPass = pass == 0u;
        Ray ray = shadowPass ? Ray(lanes[slot].shadowOrigin, lanes[slot].shadowDir)
                             : Ray(lanes[slot].rayOrigin, lanes[slot].rayDir);
        HitId id;
        bool found = findHit(ray, shadowPass ? lanes[slot].shadowDist : FLT_MAX, shadowPass, id);
        if (shadowPass) {
            lanes[slot].shadowBlocked = found ? 1u : 0u;
        } else {
            lanes[slot].found = found ? 1u : 0u;
            storeHit(slot, id);
        }
    }
    lanes[slot].loopIterations = g_loopIterations;
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

// Starts the lane's next sample (frame `frameIndex`) with its camera ray.
void startSample(inout ShadeState lane, uvec2 pixel, uint pixelIndex)
{
    lane.rng = samplerCreate(pixelIndex, lane.frameIndex, frame.seed);
    aovStartSample();
    lane.path = startPath(cameraSample(pixel, lane.rng));
    lane.shadow.pending = false;
    lane.phase = LANE_TRACE;
    ++g_loopIterations; // advancePath's count: one per segment
}

// Adds the finished sample to the pixel's sums and starts the next frame's,
// or marks the lane done after the run's last frame.
void finishStagedSample(inout ShadeState lane, uvec2 pixel, uint pixelIndex, uint slot)
{
    AccumPixel sum = accum[slot];
    Sampler rng = lane.rng;
    bool more = finishSample(sum, pixelIndex, slot, lane.frameIndex, lane.runEnd, lane.path.path.radiance, rng);
    accum[slot] = sum;
    if (!more) {
        lane.phase = LANE_DONE;
        reportLoopIterations(g_longestSample);
        return;
    }
    startSample(lane, pixel, pixelIndex);
}

// Shades what the trace stage found (or starts the run), leaving the lane
// a segment to trace, its last shadow ray, or done.
void shadeLane(inout ShadeState lane, uvec2 pixel, uint pixelIndex, uint slot)
{
    if (lane.phase == LANE_IDLE || lane.phase == LANE_DONE) {
        // The run's first shade: its first frame's camera ray.
        lane.frameIndex = frame.firstFrame;
        lane.runEnd = run.frameEnd;
        g_loopIterations = 0u;
        g_longestSample = 0u;
        g_sampleStart = 0u;
        if (lane.frameIndex >= lane.runEnd)
            lane.phase = LANE_DONE;
        else
            startSample(lane, pixel, pixelIndex);
        return;
    }
#ifdef VKRT_HAS_ALPHA
    alphaStartSample(pixelIndex, lane.frameIndex, frame.seed);
#endif
    if (lane.shadow.pending)
        addShadowedLight(lane.path, lane.shadow, lanes[slot].shadowBlocked != 0u);
    lane.shadow.pending = false;
    if (lane.phase == LANE_SHADOW) {
        finishStagedSample(lane, pixel, pixelIndex, slot);
        return;
    }
    SurfaceHit hit;
    bool found = lanes[slot].found != 0u;
    if (found)
        hit = describeHit(lane.path.ray, loadHit(slot));
    bool continues = scatterAtHit(lane.path, found, hit, lane.rng, lane.shadow);
    if (continues)
        ++g_loopIterations;
    else if (lane.shadow.pending)
        lane.phase = LANE_SHADOW;
    else
        finishStagedSample(lane, pixel, pixelIndex, slot);
}

void shadeStage(uvec2 pixel, uint pixelIndex, uint slot)
{
    // A lane done with this run reads three words, not its whole path.
    uint phase = lanes[slot].phase;
    bool sameRun = lanes[slot].runFirst == frame.firstFrame && lanes[slot].runEnd == run.frameEnd;
    if (phase == LANE_DONE && sameRun)
        return;
    ShadeState lane;
    lane.phase = phase;
    lane.frameIndex = lanes[slot].frameIndex;
    lane.runEnd = lanes[slot].runEnd;
    lane.rng = samplerCreate(pixelIndex, lane.frameIndex, frame.seed);
    lane.rng.dimension = lanes[slot].rngDimension;
    if (phase == LANE_TRACE || phase == LANE_SHADOW) {
        lane.path = loadPath(slot);
        lane.shadow = loadShadow(slot);
        g_loopIterations = lanes[slot].loopIterations;
        g_longestSample = lanes[slot].longestSample;
        g_sampleStart = lanes[slot].sampleStart;
#ifdef VKRT_AOV
        loadAov(slot);
#endif
    }
    shadeLane(lane, pixel, pixelIndex, slot);
    lanes[slot].phase = lane.phase;
    lanes[slot].runFirst = frame.firstFrame;
    lanes[slot].runEnd = lane.runEnd;
    lanes[slot].frameIndex = lane.frameIndex;
    lanes[slot].loopIterations = g_loopIterations;
    lanes[slot].longestSample = g_longestSample;
    lanes[slot].sampleStart = g_sampleStart;
    if (lane.phase == LANE_DONE)
        return;
    lanes[slot].rngDimension = lane.rng.dimension;
    storePath(slot, lane.path);
    storeShadow(slot, lane.shadow);
#ifdef VKRT_AOV
    storeAov(slot);
#endif
    lanesWithWork = 1u;
}

#endif
