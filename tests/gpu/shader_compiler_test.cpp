// Run-time GLSL compilation: readable errors, and the on-disk SPIR-V cache.
#include "gpu/ShaderCompiler.h"
#include "render/KernelVariant.h"
#include "support/TestSupport.h"

#include <fstream>
#include <optional>
#include <thread>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

/// A private copy of the shader tree that a test may edit.
fs::path copyShaderTree(const std::string& name)
{
    fs::path root = freshTempDir(name) / "shaders";
    fs::copy(defaultShaderRoot(), root, fs::copy_options::recursive);
    return root;
}

KernelSource renderKernel(const fs::path& root, std::vector<Define> defines = {})
{
    return KernelSource{root, "kernels/render.comp", std::move(defines)};
}

TEST(ShaderCompiler, ErrorsNameIncludedFileLineAndDefines)
{
    fs::path root = freshTempDir("glsl-error") / "shaders";
    writeText(root / "kernels/k.comp",
              "#version 460\n#extension GL_GOOGLE_include_directive : require\n"
              "layout(local_size_x = 1) in;\n#include \"lib/broken.glsl\"\nvoid main() { broken(); }\n");
    writeText(root / "lib/broken.glsl", "// fine\n// fine\nvoid broken() { undefinedThing = 1; }\n");
    try {
        compileGlsl(KernelSource{root, "kernels/k.comp", {{"VKRT_SOMETHING", "1"}}});
        FAIL() << "expected GpuError";
    } catch (const GpuError& e) {
        std::string message = e.what();
        EXPECT_NE(message.find("shaders/lib/broken.glsl:3"), std::string::npos) << message;
        EXPECT_NE(message.find("undefinedThing"), std::string::npos) << message;
        EXPECT_NE(message.find("VKRT_SOMETHING"), std::string::npos) << message;
        EXPECT_NE(message.find("shaders/kernels/k.comp"), std::string::npos) << message;
    }
}

TEST(ShaderCompiler, ProducesSpirv)
{
    auto spirv = compileGlsl(
        renderKernel(defaultShaderRoot(), KernelVariant{FeatureSet::everything(Integrator::Whitted)}.defines()));
    ASSERT_GT(spirv.size(), 5u);
    EXPECT_EQ(spirv[0], 0x07230203u);
}

TEST(SpirvCache, HitSkipsGlslangAndChangesMiss)
{
    fs::path root = copyShaderTree("cache-keys");
    SpirvCache cache(freshTempDir("cache-keys-store"));
    auto defines = KernelVariant{FeatureSet::everything(Integrator::Whitted)}.defines();

    uint64_t before = glslangInvocationCount();
    CompiledKernel first = compileKernelCached(renderKernel(root, defines), cache);
    EXPECT_FALSE(first.fromCache);
    EXPECT_EQ(glslangInvocationCount(), before + 1);

    CompiledKernel second = compileKernelCached(renderKernel(root, defines), cache);
    EXPECT_TRUE(second.fromCache);
    EXPECT_EQ(second.spirv, first.spirv);
    EXPECT_EQ(glslangInvocationCount(), before + 1) << "a cache hit must not run glslang";

    auto fewer = defines;
    fewer.pop_back();
    CompiledKernel otherDefines = compileKernelCached(renderKernel(root, fewer), cache);
    EXPECT_FALSE(otherDefines.fromCache);
    EXPECT_NE(otherDefines.cacheKey, first.cacheKey);

    std::ofstream(root / "lib/ray.glsl", std::ios::app) << "\n// edited\n";
    CompiledKernel edited = compileKernelCached(renderKernel(root, defines), cache);
    EXPECT_FALSE(edited.fromCache) << "an edited include must miss";
    EXPECT_NE(edited.cacheKey, first.cacheKey);
    EXPECT_EQ(glslangInvocationCount(), before + 3);
}

TEST(SpirvCache, DamagedEntryIsRecompiled)
{
    SpirvCache cache(freshTempDir("cache-damaged"));
    KernelSource source = renderKernel(defaultShaderRoot());
    CompiledKernel first = compileKernelCached(source, cache);
    std::ofstream(cache.directory() / (first.cacheKey + ".spv"), std::ios::trunc) << "garbage!";
    CompiledKernel again = compileKernelCached(source, cache);
    EXPECT_FALSE(again.fromCache);
    EXPECT_EQ(again.spirv, first.spirv);
    EXPECT_TRUE(compileKernelCached(source, cache).fromCache);
}

/// Sets an environment variable for one scope and restores it afterwards.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : m_name(name)
    {
        if (const char* old = std::getenv(name)) m_old = old;
        value ? setenv(name, value, 1) : unsetenv(name);
    }
    ~ScopedEnv() { m_old ? setenv(m_name, m_old->c_str(), 1) : unsetenv(m_name); }

private:
    const char* m_name;
    std::optional<std::string> m_old;
};

TEST(SpirvCache, DefaultDirectoryHonoursXdgCacheHome)
{
    ScopedEnv noOverride("VKRT_CACHE_DIR", nullptr);
    ScopedEnv xdg("XDG_CACHE_HOME", "/some/cache");
    EXPECT_EQ(SpirvCache::defaultDirectory(), fs::path("/some/cache/vkrt/spirv"));
    ScopedEnv explicitDir("VKRT_CACHE_DIR", "/explicit");
    EXPECT_EQ(SpirvCache::defaultDirectory(), fs::path("/explicit"));
}

// Two renders started together on an empty cache both compile and both
// succeed: cache writes are atomic renames, never partial files.
TEST(SpirvCache, ConcurrentProcessesOnColdCacheBothSucceed)
{
    fs::path dir = freshTempDir("cache-concurrent");
    ScopedEnv cacheDir("VKRT_CACHE_DIR", (dir / "cache").c_str());
    std::string scene = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/default.toml";
    ProcessResult results[2];
    std::thread a([&] {
        results[0] =
            runVkrt({"render", scene, "-o", (dir / "a.exr").string(), "--spp", "2", "--width", "32", "--height", "24"});
    });
    std::thread b([&] {
        results[1] =
            runVkrt({"render", scene, "-o", (dir / "b.exr").string(), "--spp", "2", "--width", "32", "--height", "24"});
    });
    a.join();
    b.join();
    for (const auto& r : results) EXPECT_EQ(r.exitCode, 0) << r.output;
    size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir / "cache")) {
        EXPECT_EQ(e.path().extension(), ".spv") << "leftover " << e.path();
        ++entries;
    }
    EXPECT_EQ(entries, 1u);
}

} // namespace
} // namespace vkrt::test
