#pragma once
// A SPIR-V fault injector: a shim between vkrt and the driver. It rewrites the
// SPIR-V handed to vkCreateShaderModule so that the driver runs subtly wrong
// arithmetic, to measure how much driver breakage `vkrt regress` catches
// (`vkrt regress --inject FAULT`). Pure functions on SPIR-V words, no Vulkan.
//
// Faults (one at a time):
//   scale:CLASS:EPS  every 32-bit float (scalar or vector) result of CLASS is
//                    multiplied by 1 + EPS (|EPS| < 1); CLASS is FMul, FAdd,
//                    FSub, FDiv, a GLSL.std.450 instruction: Sqrt,
//                    InverseSqrt, Exp, Log, Pow, Sin, Cos, Atan2, Acos, Exp2,
//                    Log2, Fma, or RayQueryT (the t a ray query reports)
//   scale:CLASS:EPS:1inN  the same for 1 in N results only: those whose
//                    float bits (the first component's) spirvFaultSelects,
//                    a fault that depends on the operands, as miscompiles do
//   neighbour-load[:1inN]  a load through a storage-buffer array element
//                    a[i] reads a[i + 1] instead, for every i or for the 1 in
//                    N indices that spirvFaultSelects (stores are untouched)
//   texel-offset[:1inN]  texelFetch(image, (x, y)) reads (x + 1, y), for every
//                    texel or for 1 in N (spirvFaultSelects(x + 65536 y))
//   loop-cut:N       every loop of an invocation ends once the invocation has
//                    entered loop headers N times in all (Mesa 22 lavapipe's
//                    real bug at N = 65535, counted per invocation here)
//   compare:lt-le    < and <= swapped (ordered and unordered)
//   compare:gt-ge    > and >= swapped (ordered and unordered)
//   nan-minmax       GLSL.std.450 FMin/FMax/NMin/NMax become a < b ? a : b
//                    and a > b ? a : b (b when a is NaN)
//   contract         a legal variation, not a fault: a float multiply whose
//                    only purpose is an add (a*b + c, c + a*b, a*b - c) is
//                    fused into GLSL.std.450 Fma where neither instruction is
//                    NoContraction (`precise`), as SPIR-V lets a driver do;
//                    only where the product is the add's operand itself
//                    (glslang keeps locals in memory: a product stored to a
//                    variable first stays apart), a subset of what a driver may fuse
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace vkrt {

enum class SpirvFaultKind { Scale, Compare, NanMinMax, Contract, NeighbourLoad, TexelOffset, LoopCut };

/// One fault to inject, as parseSpirvFault reads it.
struct SpirvFault {
    SpirvFaultKind kind = SpirvFaultKind::Scale;
    std::string spec; ///< as written, e.g. "scale:FMul:0.1"
    /// Scale: the instruction, a core opcode, or OpExtInst (12) with a GLSL.std.450 number.
    uint32_t opcode = 0;
    uint32_t extInstruction = 0;
    double epsilon = 0.0;
    /// Scale, NeighbourLoad, TexelOffset: the fault hits 1 in oneIn values (1: all).
    uint32_t oneIn = 1;
    /// LoopCut: the loop-header entries an invocation may make.
    uint32_t loopPasses = 0;
    /// Compare: opcode pairs exchanged with each other.
    std::vector<std::pair<uint32_t, uint32_t>> swaps;
};

/// Whether a fault of `1inN` hits the value whose 32 bits are `key`: a
/// 32-bit integer hash of the key (multiply, shift, xor twice) is a multiple
/// of N. The injected kernels compute the same in SPIR-V; tests predict
/// from it which results a fault changes.
constexpr bool spirvFaultSelects(uint32_t key, uint32_t oneIn)
{
    uint32_t h = key * 0x9E3779B1u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    return h % oneIn == 0;
}

/// The environment variable that makes every ComputeKernel inject a fault.
inline constexpr const char* kInjectFaultVariable = "VKRT_INJECT_FAULT";

/// Reads a fault spec (grammar above); InputError naming the bad part and the valid choices.
SpirvFault parseSpirvFault(const std::string& spec);

/// The module with `fault` injected (a valid module again, its id bound
/// raised as needed); `changed` receives the number of instructions changed.
/// Throws InternalError for words that are not a SPIR-V module.
std::vector<uint32_t> injectSpirvFault(std::span<const uint32_t> spirv, const SpirvFault& fault,
                                       size_t* changed = nullptr);

/// The fault $VKRT_INJECT_FAULT names, if set and not empty; an InputError
/// naming the variable if it is not a fault. Read at every call (kernels are
/// made rarely), so a test may change it between kernels.
std::optional<SpirvFault> spirvFaultFromEnvironment();

} // namespace vkrt
