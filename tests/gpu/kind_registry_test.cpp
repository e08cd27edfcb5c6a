// The registry of kinds (shared/Kinds.h): its GLSL constants equal the C++
// ones as glslang evaluates them, and every kind it lists is a kind the
// scene parser accepts, with misspellings answered from the registry's names.
#include "gpu/ShaderCompiler.h"
#include "render/KernelVariant.h"
#include "scene/SceneParser.h"
#include "shared/Bindings.h"
#include "shared/SceneTypes.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>

namespace vkrt::test {
namespace {

/// Each constant of the registry, in the order the probe kernel declares it.
std::vector<std::pair<std::string, int64_t>> cppConstants()
{
    std::vector<std::pair<std::string, int64_t>> constants;
#define VKRT_CPP_MATERIAL(KIND, Type, name, value, delta) \
    constants.emplace_back("material_" #KIND, gpu::MATERIAL_##KIND);
#define VKRT_CPP_SHAPE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    constants.emplace_back("shape_" #KIND, gpu::SHAPE_##KIND);                          \
    constants.emplace_back("capacity_" #ARRAY, gpu::UNIFORM_##ARRAY);
#define VKRT_CPP_LIGHT(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    constants.emplace_back("light_" #KIND, gpu::LIGHT_##KIND);                          \
    constants.emplace_back("capacity_" #ARRAY, gpu::UNIFORM_##ARRAY);
    VKRT_MATERIAL_KINDS(VKRT_CPP_MATERIAL)
    VKRT_SHAPE_KINDS(VKRT_CPP_SHAPE)
    VKRT_LIGHT_KINDS(VKRT_CPP_LIGHT)
#undef VKRT_CPP_MATERIAL
#undef VKRT_CPP_SHAPE
#undef VKRT_CPP_LIGHT
    constants.emplace_back("materialCount", gpu::MATERIAL_KIND_COUNT);
    constants.emplace_back("shapeCount", gpu::SHAPE_KIND_COUNT);
    constants.emplace_back("lightCount", gpu::LIGHT_KIND_COUNT);
    return constants;
}

TEST(KindRegistry, GlslConstantsEqualTheCppOnes)
{
    KernelSource source{defaultShaderRoot(), "../tests/gpu/kernels/kind_registry_reflect.comp", {}};
    std::map<std::string, int> offsets;
    for (const auto& [name, offset] : reflectBlockMemberOffsets(source)) offsets[name] = offset;
    std::string names;
    for (const auto& [name, offset] : offsets) names += name + "@" + std::to_string(offset) + " ";
    // Scalar layout: constant C is C + 1 words after the previous marker's end, then its own marker.
    int64_t previousEnd = 0;
    for (const auto& [name, value] : cppConstants()) {
        auto marker = offsets.find("RegistryBlock.end_" + name);
        ASSERT_NE(marker, offsets.end()) << name << " not reflected; glslang reported: " << names;
        int64_t glslValue = (marker->second - previousEnd) / 4 - 1;
        EXPECT_EQ(glslValue, value) << name << ": GLSL and C++ disagree";
        previousEnd = marker->second + 4;
    }
}

TEST(KindRegistry, CountsAndNamesMatchTheLists)
{
    EXPECT_EQ(kMaterialNames.size(), kMaterialKindCount);
    EXPECT_EQ(kShapeNames.size(), size_t(gpu::SHAPE_KIND_COUNT));
    EXPECT_EQ(kLightNames.size(), size_t(gpu::LIGHT_KIND_COUNT));
    EXPECT_EQ(kindName(MaterialType::Dielectric), "dielectric");
    EXPECT_EQ(kindName(ShapeKind::Plane), "plane");
    EXPECT_EQ(kindName(LightKind::TriangleLight), "triangle");
    // The materials array plus one array per shape and light kind, each with its own binding.
    const auto& arrays = sceneArrayBindings();
    EXPECT_EQ(arrays.size(), 1 + kShapeKindCount + kLightKindCount);
    std::set<uint32_t> distinct;
    for (const auto& a : arrays) distinct.insert(a.binding);
    EXPECT_EQ(distinct.size(), arrays.size());
}

// Every registry kind gets its define and binding in the all-features variant.
TEST(KindRegistry, EveryKindHasADefineAndABinding)
{
    KernelVariant uber(FeatureSet::everything(Integrator::Whitted));
    std::string defines = describeDefines(uber.defines());
    for (std::string_view name : kMaterialNames) {
        std::string define = "VKRT_MATERIAL_" + std::string(name);
        for (char& c : define) c = char(std::toupper(static_cast<unsigned char>(c)));
        EXPECT_NE(defines.find(define), std::string::npos) << define << " in " << defines;
    }
    std::vector<uint32_t> bindings = uber.bindings();
    for (const auto& a : sceneArrayBindings())
        EXPECT_NE(std::find(bindings.begin(), bindings.end(), a.binding), bindings.end()) << a.binding;
}

// Every pbr lobe of the registry is a define of the all-features variant, and
// the shader library guards code with it: a lobe added to the registry
// without its GLSL fails here.
TEST(KindRegistry, EveryPbrLobeIsADefineTheShadersUse)
{
    FeatureSet everything = FeatureSet::everything(Integrator::Path);
    std::string defines = describeDefines(KernelVariant(everything).defines());
    std::string library;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(defaultShaderRoot() / "lib"))
        if (entry.is_regular_file()) {
            std::ifstream in(entry.path());
            library += std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        }
    ASSERT_EQ(kPbrLobeNames.size(), kPbrLobeCount);
    for (std::string_view name : kPbrLobeNames) {
        std::string define = "VKRT_PBR_" + std::string(name);
        for (char& c : define) c = char(std::toupper(static_cast<unsigned char>(c)));
        EXPECT_NE(defines.find(define), std::string::npos) << define << " in " << defines;
        EXPECT_NE(library.find("#ifdef " + define), std::string::npos) << define << " guards no shader code";
    }
    // A scene without the lobe leaves it out of its variant.
    FeatureSet plain = everything;
    plain.pbrLobes[size_t(PbrLobe::Sheen)] = false;
    EXPECT_EQ(describeDefines(KernelVariant(plain).defines()).find("VKRT_PBR_SHEEN"), std::string::npos);
}

const char* kCamera = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n";

/// A valid table of each kind's required keys (beyond type/shape and material).
const std::map<std::string_view, std::string> kShapeExamples{
    {"sphere", "center = [0, 0, 0]\nradius = 1\n"},
    {"box", "min = [0, 0, 0]\nmax = [1, 1, 1]\n"},
    {"triangle", "vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n"},
    {"plane", "point = [0, 0, 0]\nnormal = [0, 1, 0]\n"},
    {"mesh", "file = "}, // + the path of a one-triangle OBJ (meshFileExample)
};

/// The `file` value of the mesh example: a one-triangle OBJ written once.
std::string meshFileExample()
{
    static const std::filesystem::path file = [] {
        const auto path = freshTempDir("kind-registry") / "triangle.obj";
        writeText(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        return path;
    }();
    return "\"" + file.string() + "\"\n";
}
const std::map<std::string_view, std::string> kLightExamples{
    {"point", "position = [0, 3, 0]\nintensity = 1\n"},
    {"triangle", "vertices = [[0, 2, 0], [1, 2, 0], [0, 2, 1]]\nradiance = 1\n"},
    {"directional", "direction = [0, -1, 0]\nirradiance = 1\n"},
    {"spot", "position = [0, 3, 0]\ndirection = [0, -1, 0]\nintensity = 1\n"},
};

TEST(KindRegistry, ParserAcceptsEveryMaterialKind)
{
    for (size_t i = 0; i < kMaterialKindCount; ++i) {
        std::string text = std::string(kCamera) + "[materials.m]\ntype = \"" + std::string(kMaterialNames[i]) + "\"\n";
        Scene scene = sceneFromText(text);
        ASSERT_EQ(scene.materials.size(), 1u);
        EXPECT_EQ(scene.materials[0].type, MaterialType(i)) << kMaterialNames[i];
    }
}

TEST(KindRegistry, ParserAcceptsEveryShapeKind)
{
    for (size_t i = 0; i < kShapeKindCount; ++i) {
        auto example = kShapeExamples.find(kShapeNames[i]);
        ASSERT_NE(example, kShapeExamples.end()) << "add an example of the new shape " << kShapeNames[i];
        std::string text = std::string(kCamera) + "[materials.m]\ntype = \"lambert\"\n[[objects]]\nshape = \"" +
                           std::string(kShapeNames[i]) + "\"\nmaterial = \"m\"\n" + example->second;
        if (kShapeNames[i] == "mesh") text += meshFileExample();
        Scene scene = sceneFromText(text);
        for (ShapeKind kind : kAllShapeKinds)
            EXPECT_EQ(scene.count(kind), kind == ShapeKind(i) ? 1u : 0u) << kShapeNames[i];
    }
}

TEST(KindRegistry, ParserAcceptsEveryLightKind)
{
    for (size_t i = 0; i < kLightKindCount; ++i) {
        auto example = kLightExamples.find(kLightNames[i]);
        ASSERT_NE(example, kLightExamples.end()) << "add an example of the new light " << kLightNames[i];
        std::string text =
            std::string(kCamera) + "[[lights]]\ntype = \"" + std::string(kLightNames[i]) + "\"\n" + example->second;
        Scene scene = sceneFromText(text);
        for (LightKind kind : kAllLightKinds)
            EXPECT_EQ(scene.count(kind), kind == LightKind(i) ? 1u : 0u) << kLightNames[i];
    }
}

std::string parseError(const std::string& text)
{
    try {
        sceneFromText(text);
    } catch (const std::exception& error) {
        return error.what();
    }
    return "";
}

template <size_t N>
std::string joined(const std::array<std::string_view, N>& names)
{
    std::string out;
    for (std::string_view name : names) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

/// Each name with its second letter doubled: close enough for a suggestion, never a kind itself.
template <size_t N>
void expectMisspellingsSuggestTheKind(const std::array<std::string_view, N>& names,
                                      const std::function<std::string(std::string)>& scene)
{
    for (std::string_view name : names) {
        std::string typo = std::string(name.substr(0, 2)) + std::string(name.substr(1));
        std::string message = parseError(scene(typo));
        EXPECT_NE(message.find("'" + typo + "'; did you mean '" + std::string(name) + "'?"), std::string::npos)
            << message;
        EXPECT_NE(message.find("(expected one of: " + joined(names) + ")"), std::string::npos) << message;
    }
}

TEST(KindRegistry, MisspelledKindsGetADidYouMeanFromTheRegistry)
{
    expectMisspellingsSuggestTheKind(kMaterialNames, [](const std::string& type) {
        return std::string(kCamera) + "[materials.m]\ntype = \"" + type + "\"\n";
    });
    expectMisspellingsSuggestTheKind(kShapeNames, [](const std::string& shape) {
        return std::string(kCamera) + "[materials.m]\ntype = \"lambert\"\n[[objects]]\nshape = \"" + shape +
               "\"\nmaterial = \"m\"\n";
    });
    expectMisspellingsSuggestTheKind(kLightNames, [](const std::string& type) {
        return std::string(kCamera) + "[[lights]]\ntype = \"" + type + "\"\n";
    });
}

// A key of another kind is named as such, from the union of the registry's key lists.
TEST(KindRegistry, KeyOfAnotherKindIsNamedAsSuch)
{
    std::string message = parseError(std::string(kCamera) + "[materials.m]\ntype = \"lambert\"\nshininess = 3\n");
    EXPECT_NE(message.find("key 'shininess' is not used by material type 'lambert'"), std::string::npos) << message;
    message =
        parseError(std::string(kCamera) + "[materials.m]\ntype = \"lambert\"\n[[objects]]\nshape = \"sphere\"\n"
                                          "material = \"m\"\ncenter = [0, 0, 0]\nradius = 1\nnormal = [0, 1, 0]\n");
    EXPECT_NE(message.find("key 'normal' is not used by shape 'sphere'"), std::string::npos) << message;
}

} // namespace
} // namespace vkrt::test
