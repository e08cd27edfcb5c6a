#ifndef VKRT_RAY_GLSL
#define VKRT_RAY_GLSL

const float FLT_MAX = 3.402823466e38;
const float PI = 3.14159265358979323846;
// How far a shadow ray towards a light at infinity (a sun) looks: as far as
// a float vector's length can be taken without overflow (its square < FLT_MAX).
const float FAR_LIGHT_DISTANCE = 1e18;
const float INV_PI = 0.31830988618379067154;

// x^e with 0^0 = 1 (GLSL leaves pow(0, 0) undefined).
float powSafe(float x, float e) { return e == 0.0 ? 1.0 : pow(max(x, 0.0), e); }

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

struct Ray {
    vec3 origin;
    vec3 dir; // unit length
};

// gamma(n) = n u / (1 - n u), u = 2^-24: the bound on the relative error of n
// chained float operations (Higham; pbrt-v4 section 6.8).
float gammaBound(int n)
{
    const float unitRoundoff = 5.96046448e-8;
    return float(n) * unitRoundoff / (1.0 - float(n) * unitRoundoff);
}

// The next float above x (below when `up` is false). Zero steps to the
// smallest normal float, since lavapipe may flush denormals.
float nextFloat(float x, bool up)
{
    if (x == 0.0)
        return up ? 1.17549435e-38 : -1.17549435e-38;
    int bits = floatBitsToInt(x);
    bool awayFromZero = (x > 0.0) == up;
    return intBitsToFloat(bits + (awayFromZero ? 1 : -1));
}

// One float step in the direction of the normal's component (none if it is 0).
float stepAlongNormal(float x, float nComponent)
{
    return nComponent == 0.0 ? x : nextFloat(x, nComponent > 0.0);
}

// Moves a point spawned on a surface off it, to the side of the unit normal
// n that the new ray travels into: by the point's error bound pError (per
// coordinate, from the intersection routine) projected on n, then one more
// float step per coordinate so rounding of the sum cannot pull it back
// (Pharr, Jakob & Humphreys, pbrt-v4 section 6.8.6). The offset scales with
// the scene by construction: no fixed epsilon, no scene-size constant.
vec3 offsetRayOrigin(vec3 p, vec3 pError, vec3 n)
{
    // precise: computed as written on every driver (lib/intersect.glsl says why).
    precise float d = dot(abs(n), pError);
    precise vec3 po = p + d * n;
    // Written out per coordinate: a loop would count against lavapipe's
    // per-invocation loop budget if the compiler kept it.
    return vec3(stepAlongNormal(po.x, n.x), stepAlongNormal(po.y, n.y), stepAlongNormal(po.z, n.z));
}

#endif
