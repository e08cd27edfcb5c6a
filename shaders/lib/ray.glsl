#ifndef VKRT_RAY_GLSL
#define VKRT_RAY_GLSL

const float FLT_MAX = 3.402823466e38;
const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

// x^e with 0^0 = 1 (GLSL leaves pow(0, 0) undefined).
float powSafe(float x, float e) { return e == 0.0 ? 1.0 : pow(max(x, 0.0), e); }

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

struct Ray {
    vec3 origin;
    vec3 dir; // unit length
};

// Moves a ray origin off the surface it was spawned on, along the geometric
// normal n (pointing to the side the new ray travels into), by a few ulps of
// the position's own magnitude: Wächter & Binder, "A Fast and Robust Method for
// Avoiding Self-Intersection", Ray Tracing Gems ch. 6. A fixed epsilon would be
// too small far from the origin and too large in tiny scenes.
vec3 offsetRayOrigin(vec3 p, vec3 n)
{
    const float originThreshold = 1.0 / 32.0;
    const float floatScale = 1.0 / 65536.0;
    const float intScale = 256.0;
    ivec3 ofi = ivec3(intScale * n);
    vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + ((p.x < 0.0) ? -ofi.x : ofi.x)),
                   intBitsToFloat(floatBitsToInt(p.y) + ((p.y < 0.0) ? -ofi.y : ofi.y)),
                   intBitsToFloat(floatBitsToInt(p.z) + ((p.z < 0.0) ? -ofi.z : ofi.z)));
    return vec3(abs(p.x) < originThreshold ? p.x + floatScale * n.x : pi.x,
                abs(p.y) < originThreshold ? p.y + floatScale * n.y : pi.y,
                abs(p.z) < originThreshold ? p.z + floatScale * n.z : pi.z);
}

#endif
