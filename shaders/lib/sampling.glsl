// Warping of uniform random numbers to directions and points.
#ifndef VKRT_SAMPLING_GLSL
#define VKRT_SAMPLING_GLSL

// acos from +, * and sqrt, to about 3e-7 radians over [-1, 1]: Abramowitz
// and Stegun 4.4.46 (|error| <= 2e-8 before float rounding). A driver's own
// acos may be off by 4096 ulp (Vulkan's precision table): at 2.4e-4 relative,
// conformant, it moved a lat-long map's horizon by a twentieth of a pixel and
// failed validation/environment-hdri (`tools/regress_power.py --ladder legal`).
// vkrt's images should not depend on how good a conformant driver's acos is.
float accurateAcos(float x)
{
    float a = min(abs(x), 1.0);
    float p = -0.0012624911;
    p = p * a + 0.0066700901;
    p = p * a - 0.0170881256;
    p = p * a + 0.0308918810;
    p = p * a - 0.0501743046;
    p = p * a + 0.0889789874;
    p = p * a - 0.2145988016;
    p = p * a + 1.5707963050;
    float r = sqrt(1.0 - a) * p;
    return x < 0.0 ? PI - r : r;
}

// Orthonormal basis around a unit vector without branches on the sign of
// n.z (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017).
void orthonormalBasis(vec3 n, out vec3 t, out vec3 b)
{
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 fromLocal(vec3 local, vec3 n)
{
    vec3 t, b;
    orthonormalBasis(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// Concentric square-to-disk map (Shirley & Chiu 1997): keeps strata compact.
vec2 concentricDisk(vec2 u)
{
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0)
        return vec2(0.0);
    float r, theta;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        theta = (PI / 4.0) * (o.y / o.x);
    } else {
        r = o.y;
        theta = (PI / 2.0) - (PI / 4.0) * (o.x / o.y);
    }
    // Vulkan lets a driver's sin and cos be off by 2^-11, so cos^2 + sin^2 may
    // pass 1 and the point leave the disk: a cosine-weighted direction would
    // then lie in the tangent plane, with density 0 (NaN weights, found with
    // `vkrt regress --inject scale:Sin:4.4e-4`). The unit vector is made unit.
    vec2 direction = vec2(cos(theta), sin(theta));
    return r * direction * inversesqrt(dot(direction, direction));
}

// Cosine-weighted hemisphere around n (Malley's method); pdf = cos / pi.
vec3 sampleCosineHemisphere(vec3 n, vec2 u)
{
    vec2 d = concentricDisk(u);
    float z = sqrt(max(0.0, 1.0 - dot(d, d)));
    return fromLocal(vec3(d, z), n);
}

// Phong lobe cos^e(alpha) around `axis`; pdf = (e + 1) / (2 pi) cos^e(alpha).
vec3 samplePhongLobe(vec3 axis, float exponent, vec2 u)
{
    float cosAlpha = pow(u.x, 1.0 / (exponent + 1.0));
    float sinAlpha = sqrt(max(0.0, 1.0 - cosAlpha * cosAlpha));
    float phi = 2.0 * PI * u.y;
    return fromLocal(vec3(sinAlpha * cos(phi), sinAlpha * sin(phi), cosAlpha), axis);
}

float phongLobePdf(float cosAlpha, float exponent)
{
    return cosAlpha > 0.0 ? (exponent + 1.0) * (0.5 * INV_PI) * powSafe(cosAlpha, exponent) : 0.0;
}

// Uniform point on triangle ABC: P = (1 - sqrt(x1)) A + sqrt(x1)(1 - x2) B
// + x2 sqrt(x1) C (Osada et al., "Shape Distributions", ACM TOG 2002, eq. 1).
vec3 sampleTriangle(vec3 a, vec3 b, vec3 c, vec2 u)
{
    float s = sqrt(u.x);
    return (1.0 - s) * a + s * (1.0 - u.y) * b + u.y * s * c;
}

#endif
