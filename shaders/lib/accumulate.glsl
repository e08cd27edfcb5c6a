#ifndef VKRT_ACCUMULATE_GLSL
#define VKRT_ACCUMULATE_GLSL

// Adds a sample to a running sum with Kahan compensation. The `precise`
// qualifiers stop the compiler from re-associating the sum away (measured on
// lavapipe: without them the compensation vanished).
void addCompensated(inout AccumPixel p, vec3 value)
{
    precise vec3 y = value - p.compensation;
    precise vec3 t = p.sum + y;
    precise vec3 lost = (t - p.sum) - y;
    p.compensation = lost;
    p.sum = t;
    p.count += 1u;
}

#if defined(VKRT_VARIANCE) && defined(VKRT_SAMPLER_SOBOL)
// Sobol' frames of one pixel are not independent, so their spread says little
// about the error of their mean. Each of the sampler's VARIANCE_BATCHES
// batches is an independently scrambled sequence, so the batch means are
// independent unbiased estimates; the host estimates the variance of the
// pixel mean from their spread (Renderer::varianceOfMean).
void accumulateMoments(uint slot, uint frameIndex, vec3 value, uint count)
{
    // The host sets the sampler's batch count VKRT_SOBOL_BATCHES to
    // VARIANCE_BATCHES (and refuses to let a test define override it); the
    // buffer is laid out for VARIANCE_BATCHES either way.
    uint batch = slot * VARIANCE_BATCHES + frameIndex % VARIANCE_BATCHES;
    AccumPixel b = batchSums[batch];
    addCompensated(b, value);
    batchSums[batch] = b;
}
#elif defined(VKRT_VARIANCE)
// Welford's update (Knuth, TAOCP vol. 2, 4.2.2): numerically stable where the
// textbook sum-of-squares formula cancels catastrophically.
void accumulateMoments(uint slot, uint frameIndex, vec3 value, uint count)
{
    MomentPixel m = moments[slot];
    vec3 delta = value - m.mean;
    m.mean += delta / float(count);
    precise vec3 term = delta * (value - m.mean) - m.m2Compensation;
    precise vec3 sum = m.m2 + term;
    precise vec3 lost = (sum - m.m2) - term;
    m.m2Compensation = lost;
    m.m2 = sum;
    moments[slot] = m;
}
#endif

// Adds one sample to the pixel's running sum `p` (which the caller stores)
// and to its variance estimate, the pixel's record `slot` of its band's
// buffers (render.comp). Non-finite samples are dropped; the host counts
// them as frames - count.
void accumulateSample(inout AccumPixel p, uint slot, uint frameIndex, vec3 value)
{
    if (any(isnan(value)) || any(isinf(value)))
        return;
    addCompensated(p, value);
#ifdef VKRT_VARIANCE
    accumulateMoments(slot, frameIndex, value, p.count);
#endif
}

#endif
