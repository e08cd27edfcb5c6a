// Radiance arriving from infinitely far away: a constant colour, a cubemap
// or a lat-long map, and importance sampling of the maps (the cubemap in the
// path integrator, the lat-long map in both): the one environment emitter.
#ifndef VKRT_ENVIRONMENT_GLSL
#define VKRT_ENVIRONMENT_GLSL

#ifdef VKRT_HAS_LATLONG
// ------------------------------------------------------------ lat-long map
// Mitsuba 3's envmap (src/scene/Scene.h, EnvironmentMap): column i at u =
// (i + 0.5) / W, row j at v = j / (H - 1), bilinear between texels and
// wrapping in u; map direction (sin phi sin theta, cos theta, -cos phi sin
// theta) at phi = 2 pi u, theta = pi v, turned into the world's by the
// rotation whose columns are u.environmentAxis*.

vec3 worldToMap(vec3 d)
{
    return vec3(dot(d, u.environmentAxisX), dot(d, u.environmentAxisY), dot(d, u.environmentAxisZ));
}

vec3 mapToWorld(vec3 m) { return m.x * u.environmentAxisX + m.y * u.environmentAxisY + m.z * u.environmentAxisZ; }

vec2 latLongUv(vec3 m)
{
    float phi = atan(m.x, -m.z);
    return vec2(phi < 0.0 ? phi * (0.5 * INV_PI) + 1.0 : phi * (0.5 * INV_PI), accurateAcos(m.y) * INV_PI);
}

vec3 latLongTexel(int i, int j) { return texelFetch(environmentLatLong, ivec2(i, j), 0).rgb; }

vec3 latLongRadiance(vec2 uv)
{
    int w = int(u.environmentExtent.x), h = int(u.environmentExtent.y);
    float x = uv.x * float(w) - 0.5, y = uv.y * float(h - 1);
    float fx = floor(x);
    int i0 = (int(fx) % w + w) % w, i1 = (i0 + 1) % w;
    int j0 = clamp(int(floor(y)), 0, h - 2);
    vec2 t = vec2(x - fx, y - float(j0));
    vec3 top = mix(latLongTexel(i0, j0), latLongTexel(i1, j0), t.x);
    vec3 bottom = mix(latLongTexel(i0, j0 + 1), latLongTexel(i1, j0 + 1), t.x);
    return mix(top, bottom, t.y);
}
#endif

vec3 environmentRadiance(vec3 dir)
{
#if defined(VKRT_HAS_LATLONG)
    return latLongRadiance(latLongUv(worldToMap(dir)));
#elif defined(VKRT_HAS_CUBEMAP)
    return textureLod(environmentMap, dir, 0.0).rgb;
#else
    return u.backgroundColor;
#endif
}

#if defined(VKRT_ENVIRONMENT_SAMPLING) && defined(VKRT_HAS_LATLONG)
// Lat-long sampling (host: src/render/EnvironmentSampling.h): a grid over
// (s, v), s = u - 0.5 / W (mod 1), whose cell (a, b) holds B x B bilinear
// cells (B = u.environmentBlock; fewer in the last column and row); a row
// is drawn from the marginal CDF (environmentCdf[0 .. rows]), a column from
// that row's conditional CDF, and then a point uniformly in the cell.

uint latLongRowStart(uint b) { return u.environmentGrid.y + 1u + b * (u.environmentGrid.x + 1u); }

// The cell's extent in s and v.
vec4 latLongCellBounds(uint a, uint b)
{
    uint w = u.environmentExtent.x, h1 = u.environmentExtent.y - 1u, block = u.environmentBlock;
    vec2 lower = vec2(float(a * block) / float(w), float(b * block) / float(h1));
    vec2 upper = vec2(float(min((a + 1u) * block, w)) / float(w), float(min((b + 1u) * block, h1)) / float(h1));
    return vec4(lower, upper);
}

// Solid-angle density of a (s, v) density `p` at map direction m: d(omega) = 2 pi^2 sin(theta) ds dv.
float latLongSolidAngle(float p, vec3 m)
{
    float sinTheta = length(m.xz);
    return sinTheta > 0.0 ? p / (2.0 * PI * PI * sinTheta) : 0.0;
}

float cdfStep(uint index) { return environmentCdf[index + 1u] - environmentCdf[index]; }

float environmentPdf(vec3 dir)
{
    vec3 m = worldToMap(dir);
    vec2 uv = latLongUv(m);
    uint w = u.environmentExtent.x, h1 = u.environmentExtent.y - 1u;
    float s = uv.x - 0.5 / float(w);
    s = s < 0.0 ? s + 1.0 : s;
    uint a = min(uint(s * float(w)), w - 1u) / u.environmentBlock;
    uint b = min(uint(uv.y * float(h1)), h1 - 1u) / u.environmentBlock;
    vec4 cell = latLongCellBounds(a, b);
    float p = cdfStep(b) * cdfStep(latLongRowStart(b) + a) / ((cell.z - cell.x) * (cell.w - cell.y));
    return latLongSolidAngle(p, m);
}

// First index i in [0, count) with cdf[first + i + 1] > target.
uint searchCdf(uint first, uint count, float target)
{
    uint lo = 0u, hi = count;
    while (lo + 1u < hi) {
        ++g_loopIterations;
        uint mid = (lo + hi) / 2u;
        if (environmentCdf[first + mid] <= target) lo = mid;
        else hi = mid;
    }
    return lo;
}

vec3 sampleEnvironment(vec3 rnd, out float pdf)
{
    uint b = searchCdf(0u, u.environmentGrid.y, rnd.x);
    uint row = latLongRowStart(b);
    uint a = searchCdf(row, u.environmentGrid.x, rnd.y);
    // The row's draw, rescaled to [0, 1), places the point in v.
    float rowP = cdfStep(b), cellP = cdfStep(row + a);
    float reused = clamp((rnd.x - environmentCdf[b]) / rowP, 0.0, 0.99999994);
    vec4 cell = latLongCellBounds(a, b);
    float s = mix(cell.x, cell.z, rnd.z), v = mix(cell.y, cell.w, reused);
    float phi = 2.0 * PI * (s + 0.5 / float(u.environmentExtent.x)), theta = PI * v;
    vec3 m = vec3(sin(phi) * sin(theta), cos(theta), -cos(phi) * sin(theta));
    pdf = latLongSolidAngle(rowP * cellP / ((cell.z - cell.x) * (cell.w - cell.y)), m);
    return mapToWorld(m);
}
#elif defined(VKRT_ENVIRONMENT_SAMPLING)
// Texels are chosen with probability proportional to luminance times solid
// angle (host: src/render/EnvironmentSampling.cpp), then a point uniformly
// inside the texel. Face conventions follow src/render/CubeFaces.h (Vulkan).

// Direction through face coordinates (s, t) in [0,1]^2, not normalized; its
// length r gives the texel's solid-angle density: d(omega) = 4 ds dt / r^3.
vec3 cubeFaceVector(uint face, vec2 st)
{
    float sc = 2.0 * st.x - 1.0, tc = 2.0 * st.y - 1.0;
    if (face == 0u) return vec3(1.0, -tc, -sc);
    if (face == 1u) return vec3(-1.0, -tc, sc);
    if (face == 2u) return vec3(sc, 1.0, tc);
    if (face == 3u) return vec3(sc, -1.0, -tc);
    if (face == 4u) return vec3(sc, -tc, 1.0);
    return vec3(-sc, -tc, -1.0);
}

// Face and (s, t) of a direction: the Vulkan cube map face selection.
uint cubeFaceOf(vec3 d, out vec2 st)
{
    vec3 a = abs(d);
    uint face;
    float sc, tc, ma;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x > 0.0 ? 0u : 1u;
        sc = d.x > 0.0 ? -d.z : d.z;
        tc = -d.y;
        ma = a.x;
    } else if (a.y >= a.z) {
        face = d.y > 0.0 ? 2u : 3u;
        sc = d.x;
        tc = d.y > 0.0 ? d.z : -d.z;
        ma = a.y;
    } else {
        face = d.z > 0.0 ? 4u : 5u;
        sc = d.z > 0.0 ? d.x : -d.x;
        tc = -d.y;
        ma = a.z;
    }
    st = clamp(0.5 * (vec2(sc, tc) / ma + 1.0), 0.0, 1.0);
    return face;
}

float texelProbability(uint index) { return environmentCdf[index + 1u] - environmentCdf[index]; }

// Solid-angle density of sampleEnvironment producing direction `dir`.
float environmentPdf(vec3 dir)
{
    vec2 st;
    uint face = cubeFaceOf(dir, st);
    uint n = u.environmentSize;
    uvec2 texel = min(uvec2(st * float(n)), uvec2(n - 1u));
    float p = texelProbability((face * n + texel.y) * n + texel.x);
    float r = length(cubeFaceVector(face, st));
    return p * float(n * n) * r * r * r * 0.25;
}

// First index i with cdf[i + 1] > u (binary search over 6 N^2 texels).
uint findTexel(float target)
{
    uint lo = 0u, hi = 6u * u.environmentSize * u.environmentSize;
    while (lo + 1u < hi) {
        ++g_loopIterations;
        uint mid = (lo + hi) / 2u;
        if (environmentCdf[mid] <= target) lo = mid;
        else hi = mid;
    }
    return lo;
}

// A direction drawn from the environment's texel distribution; pdf in solid angle.
vec3 sampleEnvironment(vec3 rnd, out float pdf)
{
    uint n = u.environmentSize;
    uint index = findTexel(rnd.x);
    uint face = index / (n * n), within = index % (n * n);
    vec2 st = (vec2(within % n, within / n) + rnd.yz) / float(n);
    vec3 v = cubeFaceVector(face, st);
    float r = length(v);
    pdf = texelProbability(index) * float(n * n) * r * r * r * 0.25;
    return v / r;
}
#endif

#endif
