// The SPIR-V fault injector (gpu/SpirvFault.h) on modules glslang compiles,
// no device needed: specs are read or refused with messages that name the
// problem, each fault changes exactly the instructions it names, and the
// result is still a valid module (SPIRV-Tools' validator, where the build
// has it).
#include "gpu/ShaderCompiler.h"
#include "gpu/SpirvFault.h"
#include "render/KernelVariant.h"
#include "support/TestSupport.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#ifdef VKRT_HAVE_SPIRV_TOOLS
#include <spirv-tools/libspirv.hpp>
#endif

namespace vkrt::test {
namespace {

// ---------------------------------------------------------------- specs

void expectSpecError(const std::string& spec, const std::vector<std::string>& fragments)
{
    try {
        parseSpirvFault(spec);
        ADD_FAILURE() << "'" << spec << "' was accepted";
    } catch (const InputError& e) {
        const std::string message = e.what();
        for (const std::string& f : fragments) EXPECT_NE(message.find(f), std::string::npos) << f << "\n" << message;
    }
}

TEST(SpirvFaultSpec, ReadsEveryForm)
{
    SpirvFault mul = parseSpirvFault("scale:FMul:0.1");
    EXPECT_EQ(mul.kind, SpirvFaultKind::Scale);
    EXPECT_EQ(mul.opcode, 133u);
    EXPECT_DOUBLE_EQ(mul.epsilon, 0.1);
    EXPECT_EQ(mul.spec, "scale:FMul:0.1");
    SpirvFault sqrt = parseSpirvFault("scale:Sqrt:-1e-3");
    EXPECT_EQ(sqrt.opcode, 12u);
    EXPECT_EQ(sqrt.extInstruction, 31u);
    EXPECT_DOUBLE_EQ(sqrt.epsilon, -1e-3);
    EXPECT_EQ(parseSpirvFault("scale:Fma:0.5").extInstruction, 50u);
    EXPECT_EQ(parseSpirvFault("compare:lt-le").kind, SpirvFaultKind::Compare);
    EXPECT_EQ(parseSpirvFault("compare:gt-ge").swaps.size(), 2u);
    EXPECT_EQ(parseSpirvFault("nan-minmax").kind, SpirvFaultKind::NanMinMax);
    EXPECT_EQ(parseSpirvFault("contract").kind, SpirvFaultKind::Contract);
    EXPECT_EQ(mul.oneIn, 1u);
    SpirvFault rare = parseSpirvFault("scale:FMul:0.5:1in1000");
    EXPECT_EQ(rare.opcode, 133u);
    EXPECT_DOUBLE_EQ(rare.epsilon, 0.5);
    EXPECT_EQ(rare.oneIn, 1000u);
    EXPECT_EQ(parseSpirvFault("scale:RayQueryT:0.01").opcode, 6018u) << "OpRayQueryGetIntersectionTKHR";
    EXPECT_EQ(parseSpirvFault("neighbour-load").kind, SpirvFaultKind::NeighbourLoad);
    EXPECT_EQ(parseSpirvFault("neighbour-load").oneIn, 1u);
    EXPECT_EQ(parseSpirvFault("neighbour-load:1in10").oneIn, 10u);
    EXPECT_EQ(parseSpirvFault("texel-offset:1in2147483648").oneIn, 2147483648u);
    EXPECT_EQ(parseSpirvFault("texel-offset").kind, SpirvFaultKind::TexelOffset);
    EXPECT_EQ(parseSpirvFault("loop-cut:65535").kind, SpirvFaultKind::LoopCut);
    EXPECT_EQ(parseSpirvFault("loop-cut:65535").loopPasses, 65535u);
}

// The hash that picks 1 in N values: deterministic, and close to 1 in N.
TEST(SpirvFaultSpec, OneInNSelectsAboutOneInN)
{
    for (uint32_t n : {1u, 7u, 100u}) {
        uint32_t selected = 0;
        constexpr uint32_t kKeys = 700000;
        for (uint32_t key = 0; key < kKeys; ++key) selected += spirvFaultSelects(key * 2654435761u + 12345u, n);
        const double expected = double(kKeys) / n, sigma = std::sqrt(expected * (1.0 - 1.0 / n));
        EXPECT_LE(std::abs(selected - expected), 5.0 * sigma + 1e-9) << "1 in " << n << ": " << selected;
    }
    // Float bits of nearby values (the scale fault's keys) are picked as evenly.
    uint32_t selected = 0;
    for (int k = 0; k < 100000; ++k) selected += spirvFaultSelects(std::bit_cast<uint32_t>(1.0f + k * 1e-5f), 10);
    EXPECT_NEAR(selected, 10000.0, 5.0 * std::sqrt(9000.0));
}

TEST(SpirvFaultSpec, RefusalsNameTheProblemAndTheChoices)
{
    expectSpecError("bogus", {"'bogus'", "unknown fault", "scale:CLASS:EPS", "compare:lt-le", "nan-minmax", "contract",
                              "neighbour-load", "texel-offset"});
    expectSpecError("", {"unknown fault"});
    expectSpecError("scale:FMull:0.1", {"unknown instruction class 'FMull'", "FMul", "InverseSqrt", "Fma"});
    expectSpecError("scale:FMul", {"scale:CLASS:EPS"});
    expectSpecError("scale:FMul:0.1:2", {"'2' is not 1inN", "1in1000"});
    expectSpecError("scale:FMul:0.1:1in0", {"out of range", "1inN"});
    expectSpecError("scale:FMul:0.1:1in2147483649", {"out of range"});
    expectSpecError("scale:FMul:0.1:1in10:5", {"scale:CLASS:EPS[:1inN]"});
    expectSpecError("neighbour-load:1inx", {"'1inx' is not 1inN"});
    expectSpecError("neighbour-load:1in-3", {"'1in-3' is not 1inN"});
    expectSpecError("texel-offset:1in", {"'1in' is not 1inN"});
    expectSpecError("texel-offset:1in5:3", {"at most 1inN", "texel-offset[:1inN]"});
    expectSpecError("loop-cut", {"loop-cut:N", "loop-cut:65535"});
    expectSpecError("loop-cut:0", {"N in '0' is out of range", "loop-cut:N"});
    expectSpecError("loop-cut:many", {"'many' is not a number of passes"});
    expectSpecError("scale:FMul:", {"EPS ''", "|EPS| < 1"});
    expectSpecError("scale:FMul:1", {"EPS 1 is out of range", "|EPS| < 1"});
    expectSpecError("scale:FMul:-1.5", {"out of range"});
    expectSpecError("scale:FMul:inf", {"EPS 'inf'", "finite"});
    expectSpecError("scale:FMul:0.1x", {"EPS '0.1x'"});
    expectSpecError("scale:FMul: 0.1", {"EPS ' 0.1' is not a finite number"}); // strtod skipped the space
    expectSpecError("scale:FMul:\t0.1", {"is not a finite number"});
    expectSpecError("compare", {"compare:lt-le", "compare:gt-ge"});
    expectSpecError("compare:lt-ge", {"'lt-ge'", "compare:lt-le", "compare:gt-ge"});
    expectSpecError("nan-minmax:1", {"no arguments"});
    expectSpecError("contract:1", {"no arguments"});
}

TEST(SpirvFaultSpec, EnvironmentIsReadAtEachCallAndNamedInErrors)
{
    unsetenv(kInjectFaultVariable);
    EXPECT_FALSE(spirvFaultFromEnvironment());
    setenv(kInjectFaultVariable, "compare:gt-ge", 1);
    ASSERT_TRUE(spirvFaultFromEnvironment());
    EXPECT_EQ(spirvFaultFromEnvironment()->spec, "compare:gt-ge");
    setenv(kInjectFaultVariable, "scale:Nope:0.1", 1);
    try {
        spirvFaultFromEnvironment();
        ADD_FAILURE() << "a bad value was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("VKRT_INJECT_FAULT"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("'Nope'"), std::string::npos) << e.what();
    }
    setenv(kInjectFaultVariable, "", 1);
    EXPECT_FALSE(spirvFaultFromEnvironment());
    unsetenv(kInjectFaultVariable);
}

// ---------------------------------------------------------------- modules

/// A one-invocation kernel over `vec4 v[]` (and `declarations`) whose main() is `body`, compiled by glslang.
std::vector<uint32_t> compileKernelBody(const std::string& name, const std::string& body,
                                        const std::string& declarations = "")
{
    const auto root = freshTempDir("spirv-fault-" + name) / "shaders";
    writeText(root / ("kernels/" + name + ".comp"), "#version 460\n"
                                                    "layout(local_size_x = 1) in;\n"
                                                    "layout(std430, binding = 0) buffer Data { vec4 v[]; };\n" +
                                                        declarations + "void main()\n{\n" + body + "}\n");
    return compileGlsl(KernelSource{root, "kernels/" + name + ".comp", {}});
}

/// Two float multiplications (a float and a vec3 one), a sqrt, comparisons
/// and scalar and vector min/max, on values the compiler cannot fold.
std::vector<uint32_t> compileSample()
{
    return compileKernelBody("sample", R"(
    float a = v[0].x, b = v[0].y;
    vec3 p = v[1].xyz, q = v[2].xyz;
    float s = a * b;
    vec3 r = p * q;
    float t = sqrt(a);
    v[3] = vec4(r, s + t);
    v[4] = vec4(a < b ? 1.0 : 0.0, a <= b ? 1.0 : 0.0, min(a, b), max(a, b));
    v[5] = vec4(min(p, q), 0.0);
    v[6] = vec4(max(p, q), 0.0);
)");
}

const std::vector<uint32_t>& sample()
{
    static const std::vector<uint32_t> spirv = compileSample();
    return spirv;
}

struct Inst {
    size_t offset;
    uint32_t opcode, words;
};

std::vector<Inst> instructions(const std::vector<uint32_t>& spirv)
{
    std::vector<Inst> list;
    for (size_t at = 5; at < spirv.size(); at += spirv[at] >> 16) {
        list.push_back({at, spirv[at] & 0xffff, spirv[at] >> 16});
        if ((spirv[at] >> 16) == 0) break;
    }
    return list;
}

size_t countOpcode(const std::vector<uint32_t>& spirv, uint32_t opcode)
{
    auto list = instructions(spirv);
    return size_t(std::count_if(list.begin(), list.end(), [&](const Inst& i) { return i.opcode == opcode; }));
}

/// OpExtInst instructions of GLSL.std.450 number `instruction` (the module imports only that set).
size_t countGlsl(const std::vector<uint32_t>& spirv, uint32_t instruction)
{
    auto list = instructions(spirv);
    return size_t(std::count_if(list.begin(), list.end(), [&](const Inst& i) {
        return i.opcode == 12 && i.words >= 5 && spirv[i.offset + 4] == instruction;
    }));
}

/// SPIRV-Tools' verdict on a module ("" when valid), or "" without SPIRV-Tools.
std::string validationErrors(const std::vector<uint32_t>& spirv)
{
#ifdef VKRT_HAVE_SPIRV_TOOLS
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2); // glslang targets Vulkan 1.2 (gpu/ShaderCompiler.cpp)
    std::string messages;
    tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t&, const char* message) {
        messages += std::string(message) + "\n";
    });
    spvtools::ValidatorOptions options;
    options.SetScalarBlockLayout(true); // as the device is asked for (GL_EXT_scalar_block_layout)
    return tools.Validate(spirv.data(), spirv.size(), options) ? "" : messages.empty() ? "invalid" : messages;
#else
    (void)spirv;
    return "";
#endif
}

constexpr uint32_t kFMul = 133, kSelect = 169, kFOrdLessThan = 184, kFOrdLessThanEqual = 188;
constexpr uint32_t kSqrt = 31, kFMin = 37, kFMax = 40;

TEST(SpirvFault, TheSampleIsValidAndHasWhatTheTestsExpect)
{
#ifdef VKRT_HAVE_SPIRV_TOOLS
    std::vector<uint32_t> broken = sample();
    broken[3] = 2; // an id bound below the ids used
    EXPECT_NE(validationErrors(broken), "") << "the validator must see a broken module";
#else
    std::cout << "SPIRV-Tools not in this build: modules are not validated\n";
#endif
    EXPECT_EQ(validationErrors(sample()), "");
    EXPECT_EQ(countOpcode(sample(), kFMul), 2u);
    EXPECT_EQ(countGlsl(sample(), kSqrt), 1u);
    EXPECT_EQ(countOpcode(sample(), kFOrdLessThan), 1u);
    EXPECT_EQ(countOpcode(sample(), kFOrdLessThanEqual), 1u);
    EXPECT_EQ(countGlsl(sample(), kFMin) + countGlsl(sample(), kFMax), 4u);
}

TEST(SpirvFault, ScaleFollowsEachMultiplicationWithOneMore)
{
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(sample(), parseSpirvFault("scale:FMul:0.1"), &changed);
    EXPECT_EQ(changed, 2u);
    EXPECT_EQ(countOpcode(out, kFMul), 4u);
    // Two unscaled results, the float constant 1.1 and its vec3.
    EXPECT_EQ(out[3], sample()[3] + 4);
    EXPECT_EQ(countOpcode(out, 43) - countOpcode(sample(), 43), 1u);
    EXPECT_EQ(countOpcode(out, 44) - countOpcode(sample(), 44), 1u);
    EXPECT_EQ(out.size(), sample().size() + 2 * 5 + 4 + 6);
    EXPECT_EQ(validationErrors(out), "");
    // Each new multiplication takes the instruction before it as its operand.
    auto list = instructions(out);
    for (size_t k = 1; k < list.size(); ++k)
        if (list[k].opcode == kFMul && list[k - 1].opcode == kFMul) {
            EXPECT_EQ(out[list[k].offset + 3], out[list[k - 1].offset + 2]);
            EXPECT_EQ(out[list[k].offset + 1], out[list[k - 1].offset + 1]);
        }
}

TEST(SpirvFault, ScaleOfAnExtendedInstruction)
{
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(sample(), parseSpirvFault("scale:Sqrt:-0.01"), &changed);
    EXPECT_EQ(changed, 1u);
    EXPECT_EQ(countOpcode(out, kFMul), 3u);
    EXPECT_EQ(countGlsl(out, kSqrt), 1u);
    EXPECT_EQ(out[3], sample()[3] + 2);
    EXPECT_EQ(validationErrors(out), "");
    EXPECT_EQ(injectSpirvFault(sample(), parseSpirvFault("scale:Exp:0.1"), &changed), sample());
    EXPECT_EQ(changed, 0u) << "no exp in the sample: nothing changes";
}

constexpr uint32_t kBitcast = 124, kUMod = 137, kVectorTimesScalar = 142, kLoad = 61, kStore = 62, kAccessChain = 65,
                   kImageFetch = 95, kIAdd = 128;

// 1 in N: the product is multiplied by a factor chosen from 1 + EPS and 1 by
// the hash of the first component's bits.
TEST(SpirvFault, ScaleOneInNSelectsTheFactorByTheResultsBits)
{
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(sample(), parseSpirvFault("scale:FMul:0.5:1in10"), &changed);
    EXPECT_EQ(changed, 2u);
    EXPECT_EQ(validationErrors(out), "");
    EXPECT_EQ(countOpcode(out, kFMul), 2u + 1u) << "the float product is scaled by FMul";
    EXPECT_EQ(countOpcode(out, kVectorTimesScalar), 1u) << "the vec3 product by VectorTimesScalar";
    EXPECT_EQ(countOpcode(out, kBitcast), 2u);
    EXPECT_EQ(countOpcode(out, kUMod), 2u);
    EXPECT_EQ(countOpcode(out, kSelect) - countOpcode(sample(), kSelect), 2u);
}

/// Loads of computed elements of a storage buffer (one as a whole vec4, one
/// through a member), a load of a constant element, and stores.
std::vector<uint32_t> compileLoadSample()
{
    return compileKernelBody("load", R"(
    int i = int(v[0].w);
    vec4 whole = v[i];
    float member = v[i + 2].y;
    v[i + 1] = whole * member;
)");
}

TEST(SpirvFault, NeighbourLoadReadsTheNextElementAndLeavesStoresAlone)
{
    const std::vector<uint32_t> clean = compileLoadSample();
    ASSERT_EQ(validationErrors(clean), "");
    for (const std::string spec : {"neighbour-load", "neighbour-load:1in3"}) {
        size_t changed = 0;
        std::vector<uint32_t> out = injectSpirvFault(clean, parseSpirvFault(spec), &changed);
        EXPECT_EQ(changed, 2u) << spec << ": v[i] and v[i + 2].y; not v[0].w (a constant index)";
        EXPECT_EQ(validationErrors(out), "") << spec;
        EXPECT_EQ(countOpcode(out, kLoad), countOpcode(clean, kLoad)) << spec;
        EXPECT_EQ(countOpcode(out, kStore), countOpcode(clean, kStore)) << spec;
        EXPECT_EQ(countOpcode(out, kAccessChain), countOpcode(clean, kAccessChain) + 2) << spec;
        EXPECT_EQ(countOpcode(out, kUMod), spec == "neighbour-load" ? 0u : 2u) << spec;
    }
    size_t changed = 0;
    EXPECT_EQ(injectSpirvFault(sample(), parseSpirvFault("neighbour-load"), &changed), sample());
    EXPECT_EQ(changed, 0u) << "the sample reads v[0], v[1], v[2]: constant indices";
}

TEST(SpirvFault, TexelOffsetMovesTheFetchedTexel)
{
    const std::vector<uint32_t> clean = compileKernelBody("fetch", "    v[1] = texelFetch(image, ivec2(v[0].xy), 0);\n",
                                                          "layout(binding = 1) uniform sampler2D image;\n");
    ASSERT_EQ(validationErrors(clean), "");
    ASSERT_EQ(countOpcode(clean, kImageFetch), 1u);
    for (const std::string spec : {"texel-offset", "texel-offset:1in4"}) {
        size_t changed = 0;
        std::vector<uint32_t> out = injectSpirvFault(clean, parseSpirvFault(spec), &changed);
        EXPECT_EQ(changed, 1u) << spec;
        EXPECT_EQ(validationErrors(out), "") << spec;
        EXPECT_EQ(countOpcode(out, kImageFetch), 1u) << spec;
        EXPECT_EQ(countOpcode(out, kIAdd) - countOpcode(clean, kIAdd), 2u) << spec << ": the key, and x + 1";
        EXPECT_EQ(countOpcode(out, kUMod), spec == "texel-offset" ? 0u : 1u) << spec;
    }
}

/// A for loop, a while loop and a do-while loop.
std::vector<uint32_t> compileLoopSample()
{
    return compileKernelBody("loops", R"(
    uint n = uint(v[0].x), a = 0u, b = 0u, c = 0u;
    for (uint k = 0u; k < n; ++k)
        ++a;
    while (b < n)
        ++b;
    do {
        ++c;
    } while (c < n);
    v[1] = vec4(a, b, c, 0.0);
)");
}

constexpr uint32_t kLoopMerge = 246, kBranchConditional = 250, kEntryPoint = 15, kVariable = 59;

TEST(SpirvFault, LoopCutMakesEveryLoopHeaderCountAndLeave)
{
    const std::vector<uint32_t> clean = compileLoopSample();
    ASSERT_EQ(validationErrors(clean), "");
    ASSERT_EQ(countOpcode(clean, kLoopMerge), 3u);
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(clean, parseSpirvFault("loop-cut:100"), &changed);
    EXPECT_EQ(changed, 3u);
    EXPECT_EQ(validationErrors(out), "");
    EXPECT_EQ(countOpcode(out, kLoopMerge), 3u);
    EXPECT_EQ(countOpcode(out, kStore) - countOpcode(clean, kStore), 3u) << "one count per header";
    EXPECT_EQ(countOpcode(out, kVariable) - countOpcode(clean, kVariable), 1u) << "one counter for all loops";
    EXPECT_EQ(countOpcode(out, kBranchConditional) - countOpcode(clean, kBranchConditional), 3u)
        << "each header's branch becomes conditional";
    // The entry point lists the counter (SPIR-V 1.4 on): its instruction is one word longer.
    const auto entryWords = [](const std::vector<uint32_t>& m) {
        for (const Inst& i : instructions(m))
            if (i.opcode == kEntryPoint) return i.words;
        return 0u;
    };
    EXPECT_EQ(entryWords(out), entryWords(clean) + 1);
    EXPECT_EQ(injectSpirvFault(sample(), parseSpirvFault("loop-cut:5"), &changed), sample());
    EXPECT_EQ(changed, 0u) << "the sample has no loop";
}

TEST(SpirvFault, CompareSwapsOpcodesAndNothingElse)
{
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(sample(), parseSpirvFault("compare:lt-le"), &changed);
    EXPECT_EQ(changed, 2u);
    ASSERT_EQ(out.size(), sample().size());
    size_t differing = 0;
    for (const Inst& i : instructions(sample())) {
        for (size_t w = 0; w < i.words; ++w) {
            if (out[i.offset + w] == sample()[i.offset + w]) continue;
            ++differing;
            EXPECT_EQ(w, 0u) << "only opcodes change";
            EXPECT_TRUE(i.opcode == kFOrdLessThan || i.opcode == kFOrdLessThanEqual) << i.opcode;
        }
    }
    EXPECT_EQ(differing, 2u);
    EXPECT_TRUE(std::equal(out.begin(), out.begin() + 5, sample().begin())) << "the header is kept";
    EXPECT_EQ(countOpcode(out, kFOrdLessThan), 1u);
    EXPECT_EQ(validationErrors(out), "");
    EXPECT_EQ(injectSpirvFault(out, parseSpirvFault("compare:lt-le")), sample()) << "swapping twice restores";
    injectSpirvFault(sample(), parseSpirvFault("compare:gt-ge"), &changed);
    EXPECT_EQ(changed, 0u) << "the sample has no > or >=";
}

TEST(SpirvFault, NanMinMaxBecomesCompareAndSelect)
{
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(sample(), parseSpirvFault("nan-minmax"), &changed);
    EXPECT_EQ(changed, 4u);
    EXPECT_EQ(countGlsl(out, kFMin) + countGlsl(out, kFMax), 0u);
    EXPECT_EQ(countOpcode(out, kSelect) - countOpcode(sample(), kSelect), 4u);
    EXPECT_EQ(countOpcode(out, kFOrdLessThan), 1u + 2u);
    EXPECT_EQ(countOpcode(out, 186), 2u) << "max: OpFOrdGreaterThan";
    EXPECT_EQ(validationErrors(out), "");
}

/// Products that feed additions: plain, precise, subtracted, and one whose
/// product is used again.
std::vector<uint32_t> compileContractionSample()
{
    return compileKernelBody("contract", R"(
    float a = v[0].x, b = v[0].y, c = v[0].z;
    vec3 p = v[1].xyz, q = v[2].xyz, o = v[3].xyz;
    float plain = c + a * b;
    vec3 vector = p * q + o;
    float subtracted = a * c - b;
    // glslang marks every operation that feeds a precise value NoContraction,
    // buffers included: from v, that would be all of them; from an input, this one.
    float i = float(gl_GlobalInvocationID.x);
    precise float kept = i * 1.5 + 0.25;
    v[4] = vec4(vector, plain);
    v[5] = vec4(subtracted, kept, 0.0, 0.0);
)");
}

constexpr uint32_t kFma = 50, kFNegate = 127, kFAdd = 129, kFSub = 131;

// contract is the legal variation: each product that only feeds an add or a
// subtraction becomes one Fma, except where `precise` forbids it.
TEST(SpirvFault, ContractFusesProductsIntoAddsUnlessPrecise)
{
    const std::vector<uint32_t> clean = compileContractionSample();
    ASSERT_EQ(validationErrors(clean), "");
    ASSERT_EQ(countGlsl(clean, kFma), 0u);
    ASSERT_EQ(countOpcode(clean, kFAdd), 3u);
    ASSERT_EQ(countOpcode(clean, kFSub), 1u);
    size_t changed = 0;
    std::vector<uint32_t> out = injectSpirvFault(clean, parseSpirvFault("contract"), &changed);
    EXPECT_EQ(changed, 3u) << "c + a*b, p*q + o and a*c - b; not the precise i*1.5 + 0.25";
    EXPECT_EQ(countGlsl(out, kFma), 3u);
    EXPECT_EQ(countOpcode(out, kFAdd), 1u) << "the precise addition stays";
    EXPECT_EQ(countOpcode(out, kFSub), 0u);
    EXPECT_EQ(countOpcode(out, kFNegate), 1u) << "a*c - b is Fma(a, c, -b)";
    EXPECT_EQ(validationErrors(out), "");
    EXPECT_EQ(injectSpirvFault(sample(), parseSpirvFault("contract"), &changed), sample());
    EXPECT_EQ(changed, 0u) << "the sample's s + t reads s from a variable: no product feeds an add directly";
}

// Every fault on the path tracer's all-features kernel: the module stays valid,
// and the common instructions are found.
TEST(SpirvFault, EveryFaultKeepsTheRenderKernelValid)
{
    KernelVariant variant{FeatureSet::everything(Integrator::Path)};
    variant.variance = true;
    const std::vector<uint32_t> kernel =
        compileGlsl(KernelSource{defaultShaderRoot(), "kernels/render.comp", variant.defines()});
    ASSERT_EQ(validationErrors(kernel), "");
    const std::vector<std::string> classes{"FMul", "FAdd", "FSub", "FDiv",  "Sqrt", "InverseSqrt", "Exp",  "Log",
                                           "Pow",  "Sin",  "Cos",  "Atan2", "Acos", "Exp2",        "Log2", "Fma"};
    std::vector<std::string> specs{
        "compare:lt-le",          "compare:gt-ge",         "nan-minmax",           "contract",
        "neighbour-load",         "neighbour-load:1in100", "texel-offset",         "texel-offset:1in9",
        "scale:FMul:0.5:1in1000", "scale:Sqrt:-0.9:1in7",  "scale:RayQueryT:0.01", "loop-cut:65535"};
    for (const std::string& c : classes) specs.push_back("scale:" + c + ":-0.001");
    for (const std::string& spec : specs) {
        size_t changed = 0;
        std::vector<uint32_t> out = injectSpirvFault(kernel, parseSpirvFault(spec), &changed);
        EXPECT_EQ(validationErrors(out), "") << spec;
        const bool common = spec.find("FMul") != std::string::npos || spec.find("compare") != std::string::npos ||
                            spec.find("neighbour-load") != std::string::npos || spec == "loop-cut:65535";
        if (common || spec == "nan-minmax" || spec == "contract") {
            EXPECT_GT(changed, 0u) << spec;
        }
    }
}

TEST(SpirvFault, MalformedModulesAreRefused)
{
    const SpirvFault fault = parseSpirvFault("scale:FMul:0.1");
    std::vector<uint32_t> words = sample();
    words[0] = 0x03022307;
    EXPECT_THROW(injectSpirvFault(words, fault), InternalError) << "byte-swapped magic";
    EXPECT_THROW(injectSpirvFault(std::vector<uint32_t>(sample().begin(), sample().begin() + 4), fault), InternalError);
    words = sample();
    words[5] &= 0xffff; // a word count of zero
    EXPECT_THROW(injectSpirvFault(words, fault), InternalError);
    words = sample();
    words[5] |= 0xfff0u << 16; // the first instruction runs past the end
    EXPECT_THROW(injectSpirvFault(words, fault), InternalError);
    // An instruction nobody knows is copied as it is.
    words = sample();
    words.push_back(2u << 16 | 0xfffe);
    words.push_back(7);
    std::vector<uint32_t> out = injectSpirvFault(words, parseSpirvFault("compare:gt-ge"));
    EXPECT_EQ(out, words);
}

} // namespace
} // namespace vkrt::test
