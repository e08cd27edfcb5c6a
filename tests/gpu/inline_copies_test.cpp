// How many copies of each traversal the path kernel holds once every call is
// inlined, as lavapipe (and most drivers) compile it: its cold compile grows
// with each copy of a BVH walk (docs/performance.md, round four). With vkrt's
// own BVH, the path loop traces its segments and its shadow rays through one
// call site (shaders/lib/path.glsl: advancePath), so each walk is there once.
#include "gpu/ShaderCompiler.h"
#include "render/KernelVariant.h"
#include "support/TestSupport.h"

#include <map>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

/// The call graph of a SPIR-V module: calls[caller][callee] = call sites,
/// the entry point and each function's name (OpName, which glslang writes
/// as the GLSL name followed by its parameter types).
struct CallGraph {
    std::map<uint32_t, std::map<uint32_t, int>> calls;
    std::map<uint32_t, std::string> names;
    uint32_t entry = 0;

    /// How many copies of function `id` full inlining makes from the entry point.
    long copies(uint32_t id) const
    {
        if (id == entry) return 1;
        long total = 0;
        for (const auto& [caller, callees] : calls) {
            auto site = callees.find(id);
            if (site != callees.end()) total += site->second * copies(caller);
        }
        return total;
    }

    /// The copies of every function whose GLSL name is `name`.
    long copiesOf(const std::string& name) const
    {
        long total = 0;
        for (const auto& [id, full] : names)
            if (full.rfind(name + "(", 0) == 0) total += copies(id);
        return total;
    }
};

std::string literalString(const std::vector<uint32_t>& words, size_t first, size_t end)
{
    std::string text;
    for (size_t w = first; w < end; ++w)
        for (int byte = 0; byte < 4; ++byte) {
            char c = char((words[w] >> (8 * byte)) & 0xffu);
            if (c == '\0') return text;
            text += c;
        }
    return text;
}

CallGraph callGraph(const std::vector<uint32_t>& spirv)
{
    constexpr uint32_t kOpName = 5, kOpEntryPoint = 15, kOpFunction = 54, kOpFunctionCall = 57;
    CallGraph graph;
    uint32_t current = 0;
    for (size_t at = 5; at < spirv.size();) {
        uint32_t opcode = spirv[at] & 0xffffu;
        size_t count = spirv[at] >> 16;
        if (count == 0 || at + count > spirv.size()) {
            ADD_FAILURE() << "malformed SPIR-V at word " << at;
            break;
        }
        if (opcode == kOpName) graph.names[spirv[at + 1]] = literalString(spirv, at + 2, at + count);
        if (opcode == kOpEntryPoint) graph.entry = spirv[at + 2];
        if (opcode == kOpFunction) current = spirv[at + 2];
        if (opcode == kOpFunctionCall) ++graph.calls[current][spirv[at + 3]];
        at += count;
    }
    return graph;
}

CallGraph kernelCalls(Integrator integrator, bool lightTable = true)
{
    FeatureSet features = FeatureSet::everything(integrator);
    features.lightTable = lightTable;
    KernelVariant variant{features};
    return callGraph(compileGlsl(KernelSource{defaultShaderRoot(), "kernels/render.comp", variant.defines()}));
}

CallGraph pathKernelCalls() { return kernelCalls(Integrator::Path); }

TEST(InlineCopies, PathKernelHoldsOneCopyOfTheOwnBvhWalk)
{
    CallGraph graph = pathKernelCalls();
    ASSERT_NE(graph.entry, 0u);
    // The function counted must exist, or a rename would make this pass.
    EXPECT_GT(graph.copiesOf("advancePath"), 0);
    EXPECT_EQ(graph.copiesOf("traverseTop"), 1);
    EXPECT_EQ(graph.copiesOf("traverseMesh"), 1);
}

// Every material's eval and pdf once in the path kernel: the light candidates
// and the BSDF sample share one evaluation site (shaders/lib/path.glsl:
// scatterAtVertex), with every kind of light, the emitters and the
// environment map in the variant.
TEST(InlineCopies, PathKernelEvaluatesTheBsdfAtOneSite)
{
    CallGraph graph = pathKernelCalls();
    EXPECT_GT(graph.copiesOf("lightCandidate"), 0);
    EXPECT_EQ(graph.copiesOf("evalBsdf"), 1);
    EXPECT_EQ(graph.copiesOf("pdfBsdf"), 1);
    EXPECT_EQ(graph.copiesOf("evalPbr"), 1);
    // The bilinear lookup's four taps come from one fetch site per lookup.
    EXPECT_EQ(graph.copiesOf("fetchTexel"), graph.copiesOf("filterTextureLevel"));
}

// The Whitted kernel's lights are one loop (shaders/lib/lights.glsl:
// whittedDirectLight): one evaluation site there and one for the BSDF sample,
// and one shadow-ray walk beside the camera and bounce rays' one. The light
// table's reservoir, in the variants of scenes with many lights, adds one of
// each.
TEST(InlineCopies, WhittedKernelEvaluatesEachLightAtOneSite)
{
    CallGraph graph = kernelCalls(Integrator::Whitted, false);
    EXPECT_GT(graph.copiesOf("whittedDirectLight"), 0);
    EXPECT_EQ(graph.copiesOf("evalBsdf"), 2);
    EXPECT_EQ(graph.copiesOf("transmittanceFromSurface"), 1);
    EXPECT_EQ(graph.copiesOf("findHit"), 2);
    CallGraph table = kernelCalls(Integrator::Whitted, true);
    EXPECT_EQ(table.copiesOf("evalBsdf"), 3);
    EXPECT_EQ(table.copiesOf("findHit"), 3);
}

} // namespace
} // namespace vkrt::test
