// Owen-scrambled Sobol' sampler: a drop-in alternative to lib/random.glsl's
// pcg4d sampler, with the same API (Sampler, samplerCreate, sampleNext4D/2D/1D)
// and the same determinism: every value is a function of (pixel, frame, seed,
// draw). Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020:
//  - points: the first four Sobol' dimensions (Joe & Kuo's direction numbers);
//    dimension 0 is the van der Corput sequence (the index's bits reversed);
//  - randomization: each dimension is Owen-scrambled (nested uniform scramble)
//    by a Laine-Karras hash seeded from (pixel, draw, seed, batch);
//  - padding: each sampleNext4D call (a "draw") first shuffles the sample index
//    with an Owen scramble of its own, so successive draws are independent
//    randomizations, while every power-of-two block of one pixel's samples
//    stays a (0,m,2)-net in dimensions (0,1) of every draw.
// Unbiased: for any point, an Owen scramble with a uniform seed makes each
// digit a fresh seed bit xor a function of the digits before it, so every
// value is uniform on the 2^24 floats k / 2^24 in [0, 1).
//
// Error estimates. Frames of one pixel are no longer independent, so the
// per-frame Welford variance (lib/accumulate.glsl) no longer estimates the
// error of the mean: it measures the Monte Carlo variance, far above the true
// error where the nets help (x660 at 64 spp and x73,000 at 1024 spp for a
// smooth 2D integrand) and below it (x0.6) for an integrand that only couples
// two draws, whose pairing by nested permutations is a little worse than a
// random one. VKRT_SOBOL_BATCHES = K (a power of two, default 1) makes frame f
// sample f / K of batch f % K, each batch with its own seeds: the K batch means
// are then independent unbiased estimates, and
// sum_b (mean_b - mean)^2 / (K (K - 1)), with K - 1 degrees of freedom,
// estimates the variance of the pixel mean (tests/gpu/sobol_test.cpp; measured
// within 0.85..1.12 of the true error for K = 2..32 at 64..1024 spp). Splitting
// costs accuracy: K sequences of n/K points have about K^(a-1) times the error
// of one of n points when the error falls like n^-a (at 1024 spp with K = 8:
// x2.3 for a discontinuous 2D integrand, x33 for a smooth one, x1 across draws).
// The renderer sets K = VARIANCE_BATCHES (shared/Bindings.h) whenever an
// error estimate is asked for, and 1 otherwise (docs/convergence.md).
#ifndef VKRT_SOBOL_GLSL
#define VKRT_SOBOL_GLSL

#include "lib/pcg.glsl"

#ifndef VKRT_SOBOL_BATCHES
#define VKRT_SOBOL_BATCHES 1
#endif
#if VKRT_SOBOL_BATCHES < 1 || (VKRT_SOBOL_BATCHES & (VKRT_SOBOL_BATCHES - 1)) != 0
#error VKRT_SOBOL_BATCHES must be a power of two
#endif

// Sobol' points with 24 index bits and 24 digits (the output has 24 bits): a
// pixel's first 2^24 samples (per batch) are one sequence. Later ones stay
// uniform and stratified: the shuffle permutes each aligned run of 2^24 indices
// onto all 2^24 points, so each run is a net of its own.
const uint SOBOL_INDEX_MASK = 0x00ffffffu;

// Points are built "reversed": digit k of a coordinate (its 2^-(k+1) bit) sits
// at bit k, so that the Owen scramble below needs no bit reversal of its input.
// Dimension 0 (van der Corput) is then the index itself. Dimension 1's
// generator matrix is Pascal's triangle mod 2: digit k is the xor of the index
// bits c whose binary digits include k's (Lucas' theorem), a superset sum done
// in five shift-and-xor steps. Dimensions 2 and 3 xor one column per index bit:
// Joe & Kuo's direction numbers (new-joe-kuo-6.21201: s = 2, a = 1, m = {1, 3}
// and s = 3, a = 1, m = {1, 3, 1}, extended by the Bratley-Fox recurrence),
// reversed, 24 digits; checked against SciPy's Sobol' engine and, in
// tests/gpu/sobol_test.cpp, against a C++ generator.
const uvec2 SOBOL_REVERSED_COLUMNS[24] = uvec2[24](
    uvec2(0x000001u, 0x000001u), uvec2(0x000003u, 0x000003u), uvec2(0x000006u, 0x000004u), uvec2(0x000009u, 0x00000au),
    uvec2(0x000017u, 0x00001fu), uvec2(0x00003au, 0x00002eu), uvec2(0x000071u, 0x000045u), uvec2(0x0000a3u, 0x0000c9u),
    uvec2(0x000116u, 0x00011bu), uvec2(0x000339u, 0x0002a4u), uvec2(0x000677u, 0x00079au), uvec2(0x0009aau, 0x000b67u),
    uvec2(0x001601u, 0x00101eu), uvec2(0x003903u, 0x00302du), uvec2(0x007706u, 0x004041u), uvec2(0x00aa09u, 0x00a0c3u),
    uvec2(0x010117u, 0x01f104u), uvec2(0x03033au, 0x02e28au), uvec2(0x060671u, 0x0457dfu), uvec2(0x0909a3u, 0x0c9baeu),
    uvec2(0x171616u, 0x11a105u), uvec2(0x3a3939u, 0x2a7289u), uvec2(0x717777u, 0x79e7dbu), uvec2(0xa3aaaau, 0xb6dba4u));

// Adds column `bit` when that bit of the index is set (the arithmetic shift
// spreads the bit into an all-ones or all-zeros mask). Written out rather than
// looped: lavapipe counts every loop iteration against its per-invocation
// budget (NUMERICS.md), and constant indices keep the table out of memory.
#define VKRT_SOBOL_COLUMN(bit) zw ^= SOBOL_REVERSED_COLUMNS[bit] & uvec2(uint(int(index << (31 - (bit))) >> 31));

/// Sobol' point `index` (< 2^24) in dimensions 0..3, reversed (digit k at bit k).
uvec4 sobolReversed4D(uint index)
{
    uint pascal = index;
    pascal ^= (pascal >> 1u) & 0x55555555u;
    pascal ^= (pascal >> 2u) & 0x33333333u;
    pascal ^= (pascal >> 4u) & 0x0f0f0f0fu;
    pascal ^= (pascal >> 8u) & 0x00ff00ffu;
    pascal ^= (pascal >> 16u) & 0x0000ffffu;
    uvec2 zw = uvec2(0u);
    VKRT_SOBOL_COLUMN(0) VKRT_SOBOL_COLUMN(1) VKRT_SOBOL_COLUMN(2) VKRT_SOBOL_COLUMN(3)
    VKRT_SOBOL_COLUMN(4) VKRT_SOBOL_COLUMN(5) VKRT_SOBOL_COLUMN(6) VKRT_SOBOL_COLUMN(7)
    VKRT_SOBOL_COLUMN(8) VKRT_SOBOL_COLUMN(9) VKRT_SOBOL_COLUMN(10) VKRT_SOBOL_COLUMN(11)
    VKRT_SOBOL_COLUMN(12) VKRT_SOBOL_COLUMN(13) VKRT_SOBOL_COLUMN(14) VKRT_SOBOL_COLUMN(15)
    VKRT_SOBOL_COLUMN(16) VKRT_SOBOL_COLUMN(17) VKRT_SOBOL_COLUMN(18) VKRT_SOBOL_COLUMN(19)
    VKRT_SOBOL_COLUMN(20) VKRT_SOBOL_COLUMN(21) VKRT_SOBOL_COLUMN(22) VKRT_SOBOL_COLUMN(23)
    return uvec4(index, pascal, zw);
}

#undef VKRT_SOBOL_COLUMN

/// Unscrambled Sobol' point as 32-bit fractions (24 digits), for tests.
uvec4 sobolPoint4D(uint index) { return bitfieldReverse(sobolReversed4D(index & SOBOL_INDEX_MASK)); }

// Laine & Karras, "Stratified sampling for stochastic transparency", EGSR 2011,
// with Burley's constants, on reversed digits. Each step changes bit k only by
// a function of bits below k (adding, or xor with a product by an even
// constant), so it is a bijection, and it flips digit k by a function of the
// digits before it: an Owen scramble. Bit k of the result is seed bit k xor a
// function of lower input and seed bits, hence uniform when the seed is.
uvec4 laineKarrasPermutation(uvec4 x, uvec4 seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/// Owen-scrambles the sample index, most significant bit first (Burley 2020):
/// every aligned block of 2^m indices maps onto an aligned block, so every
/// power-of-two block of a pixel's samples stays a net. (Scalar work in lane x;
/// the compiler drops the others.)
uint sobolShuffle(uint index, uint seed)
{
    return bitfieldReverse(laineKarrasPermutation(uvec4(bitfieldReverse(index)), uvec4(seed)).x) & SOBOL_INDEX_MASK;
}

/// lowbias32 (C. Wellons, "Hash function prospector", 2018): a bijective mixer.
uint sobolMix(uint x)
{
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

struct Sampler {
    uint pixelIndex;
    uint frameIndex;
    uint seed;
    uint dimension; ///< index of the next 4D draw
};

Sampler samplerCreate(uint pixelIndex, uint frameIndex, uint seed)
{
    return Sampler(pixelIndex, frameIndex, seed, 0u);
}

/// Sample `index` of the 4D sequence that the seeds randomize, as 32-bit
/// fractions (their 24 high bits are the scrambled digits of the point).
uvec4 shuffledScrambledSobol4D(uint index, uint shuffleSeed, uvec4 scrambleSeeds)
{
    uvec4 digits = sobolReversed4D(sobolShuffle(index, shuffleSeed));
    return bitfieldReverse(laineKarrasPermutation(digits, scrambleSeeds));
}

vec4 sampleNext4D(inout Sampler s)
{
    uint batch = s.frameIndex % uint(VKRT_SOBOL_BATCHES);
    uint index = s.frameIndex / uint(VKRT_SOBOL_BATCHES);
    uvec4 scrambleSeeds = pcg4d(uvec4(s.pixelIndex, s.dimension, s.seed, batch));
    // pcg4d is a bijection, so a fifth seed is a function of these four in any
    // case; mixing their xor gives one unrelated to each of them.
    uint shuffleSeed = sobolMix(scrambleSeeds.x ^ scrambleSeeds.y ^ scrambleSeeds.z ^ scrambleSeeds.w);
    s.dimension += 1u;
    uvec4 bits = shuffledScrambledSobol4D(index, shuffleSeed, scrambleSeeds);
    return vec4(bits >> 8u) * (1.0 / 16777216.0); // 24 high bits: exact, < 1
}

// Same draws as sampleNext4D (dimensions 0 and 1 are the (0,2)-sequence pair);
// the compiler drops the unused lanes.
vec2 sampleNext2D(inout Sampler s) { return sampleNext4D(s).xy; }
float sampleNext1D(inout Sampler s) { return sampleNext4D(s).x; }

#endif
