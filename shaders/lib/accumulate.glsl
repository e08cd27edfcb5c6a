#ifndef VKRT_ACCUMULATE_GLSL
#define VKRT_ACCUMULATE_GLSL

#ifdef VKRT_VARIANCE
// Welford's update (Knuth, TAOCP vol. 2, 4.2.2): numerically stable where the
// textbook sum-of-squares formula cancels catastrophically.
void accumulateMoments(uint pixelIndex, vec3 value, uint count)
{
    MomentPixel m = moments[pixelIndex];
    vec3 delta = value - m.mean;
    m.mean += delta / float(count);
    precise vec3 term = delta * (value - m.mean) - m.m2Compensation;
    precise vec3 sum = m.m2 + term;
    precise vec3 lost = (sum - m.m2) - term;
    m.m2Compensation = lost;
    m.m2 = sum;
    moments[pixelIndex] = m;
}
#endif

// Adds one sample to the pixel's running sum with Kahan compensation. The
// `precise` qualifiers stop the compiler from re-associating the sum away
// (measured on lavapipe: without them the compensation vanished).
// Non-finite samples are dropped; the host counts them as frames - count.
void accumulateSample(uint pixelIndex, vec3 value)
{
    if (any(isnan(value)) || any(isinf(value)))
        return;
    AccumPixel p = accum[pixelIndex];
    precise vec3 y = value - p.compensation;
    precise vec3 t = p.sum + y;
    precise vec3 lost = (t - p.sum) - y;
    p.compensation = lost;
    p.sum = t;
    p.count += 1u;
    accum[pixelIndex] = p;
#ifdef VKRT_VARIANCE
    accumulateMoments(pixelIndex, value, p.count);
#endif
}

#endif
