#ifndef VKRT_ACCUMULATE_GLSL
#define VKRT_ACCUMULATE_GLSL

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
}

#endif
