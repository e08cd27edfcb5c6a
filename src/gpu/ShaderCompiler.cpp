#include "gpu/ShaderCompiler.h"

#include "util/Error.h"
#include "util/Hash.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>

#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

std::atomic<uint64_t> g_glslangInvocations{0};

std::optional<std::string> readTextFile(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// Names a shader file in messages as "shaders/lib/x.glsl".
std::string displayName(const std::string& relative) { return "shaders/" + relative; }

/// Resolves `#include "x"` first beside the including file, then at the
/// shader root; reports files as shaders/<path> so messages read file:line.
class RootedIncluder : public glslang::TShader::Includer {
public:
    explicit RootedIncluder(fs::path root) : m_root(std::move(root)) {}

    IncludeResult* includeLocal(const char* header, const char* includer, size_t) override
    {
        std::string includerRelative = includer ? stripPrefix(includer) : "";
        fs::path besideIncluder = fs::path(includerRelative).parent_path() / header;
        for (const fs::path& candidate : {besideIncluder, fs::path(header)}) {
            auto text = readTextFile(m_root / candidate);
            if (text) return makeResult(candidate.lexically_normal().generic_string(), std::move(*text));
        }
        return nullptr;
    }

    IncludeResult* includeSystem(const char* header, const char* includer, size_t depth) override
    {
        return includeLocal(header, includer, depth);
    }

    void releaseInclude(IncludeResult* result) override
    {
        if (!result) return;
        delete static_cast<std::string*>(result->userData);
        delete result;
    }

private:
    fs::path m_root;

    static std::string stripPrefix(const std::string& name)
    {
        return name.rfind("shaders/", 0) == 0 ? name.substr(8) : name;
    }

    IncludeResult* makeResult(const std::string& relative, std::string text)
    {
        auto* owned = new std::string(std::move(text));
        return new IncludeResult(displayName(relative), owned->data(), owned->size(), owned);
    }
};

void initializeGlslangOnce()
{
    static std::once_flag once;
    std::call_once(once, [] { glslang::InitializeProcess(); });
}

std::string preambleFor(const std::vector<Define>& defines)
{
    std::string preamble;
    for (const auto& [name, value] : defines) preamble += "#define " + name + " " + value + "\n";
    return preamble;
}

std::string variantSuffix(const KernelSource& source)
{
    return "\n(kernel " + displayName(source.entryFile) + ", defines: " + describeDefines(source.defines) + ")";
}

} // namespace

fs::path defaultShaderRoot()
{
    if (const char* env = std::getenv("VKRT_SHADER_DIR")) return env;
    if (fs::exists(fs::path(VKRT_SOURCE_SHADER_DIR) / "kernels")) return VKRT_SOURCE_SHADER_DIR;
    return VKRT_INSTALLED_SHADER_DIR;
}

std::string describeDefines(const std::vector<Define>& defines)
{
    if (defines.empty()) return "(none)";
    std::string text;
    for (const auto& [name, value] : defines) {
        if (!text.empty()) text += " ";
        text += value.empty() || value == "1" ? name : name + "=" + value;
    }
    return text;
}

std::string glslangVersion()
{
    return std::to_string(GLSLANG_VERSION_MAJOR) + "." + std::to_string(GLSLANG_VERSION_MINOR) + "." +
           std::to_string(GLSLANG_VERSION_PATCH);
}

uint64_t glslangInvocationCount() { return g_glslangInvocations.load(); }

namespace {

/// Parses and links one compute kernel; the shader must outlive the program.
struct LinkedKernel {
    glslang::TShader shader{EShLangCompute};
    glslang::TProgram program;
};

std::unique_ptr<LinkedKernel> parseAndLink(const KernelSource& source)
{
    initializeGlslangOnce();
    auto text = readTextFile(source.shaderRoot / source.entryFile);
    if (!text) throw GpuError("cannot read kernel " + (source.shaderRoot / source.entryFile).string());

    auto linked = std::make_unique<LinkedKernel>();
    glslang::TShader& shader = linked->shader;
    const char* strings[] = {text->c_str()};
    std::string name = displayName(source.entryFile);
    const char* names[] = {name.c_str()};
    shader.setStringsWithLengthsAndNames(strings, nullptr, names, 1);
    std::string preamble = preambleFor(source.defines);
    shader.setPreamble(preamble.c_str());
    shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
    auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    RootedIncluder includer(source.shaderRoot);
    if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
        throw GpuError("GLSL compilation failed:\n" + std::string(shader.getInfoLog()) + variantSuffix(source));
    linked->program.addShader(&shader);
    if (!linked->program.link(messages))
        throw GpuError("GLSL link failed:\n" + std::string(linked->program.getInfoLog()) + variantSuffix(source));
    return linked;
}

} // namespace

std::vector<uint32_t> compileGlsl(const KernelSource& source)
{
    ++g_glslangInvocations;
    auto linked = parseAndLink(source);
    std::vector<uint32_t> spirv;
    glslang::SpvOptions options;
    options.disableOptimizer = false;
    glslang::GlslangToSpv(*linked->program.getIntermediate(EShLangCompute), spirv, &options);
    return spirv;
}

std::vector<std::pair<std::string, int>> reflectBlockMemberOffsets(const KernelSource& source)
{
    auto linked = parseAndLink(source);
    glslang::TProgram& program = linked->program;
    if (!program.buildReflection(EShReflectionAllBlockVariables | EShReflectionSeparateBuffers))
        throw GpuError("glslang reflection failed" + variantSuffix(source));
    std::vector<std::pair<std::string, int>> offsets;
    for (int i = 0; i < program.getNumUniformVariables(); ++i)
        offsets.emplace_back(program.getUniform(i).name, program.getUniform(i).offset);
    for (int i = 0; i < program.getNumBufferVariables(); ++i)
        offsets.emplace_back(program.getBufferVariable(i).name, program.getBufferVariable(i).offset);
    return offsets;
}

std::string kernelCacheKey(const KernelSource& source)
{
    std::vector<fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(source.shaderRoot))
        if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    Fnv1a64 hash;
    hash.addField("vkrt-spirv-cache-v1").addField(glslangVersion()).addField(source.entryFile);
    for (const auto& [name, value] : source.defines) hash.addField(name).addField(value);
    for (const auto& file : files)
        hash.addField(fs::relative(file, source.shaderRoot).generic_string()).addField(readTextFile(file).value_or(""));
    return toHex(hash.value());
}

SpirvCache::SpirvCache(fs::path directory) : m_directory(std::move(directory)) {}

fs::path SpirvCache::defaultDirectory()
{
    if (const char* dir = std::getenv("VKRT_CACHE_DIR"); dir && *dir) return dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "vkrt" / "spirv";
    if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "vkrt" / "spirv";
    return fs::temp_directory_path() / "vkrt-cache" / "spirv";
}

fs::path SpirvCache::pathFor(const std::string& key) const { return m_directory / (key + ".spv"); }

std::optional<std::vector<uint32_t>> SpirvCache::load(const std::string& key) const
{
    auto bytes = readTextFile(pathFor(key));
    constexpr uint32_t kSpirvMagic = 0x07230203;
    if (!bytes || bytes->size() < 20 || bytes->size() % 4 != 0) return std::nullopt;
    std::vector<uint32_t> words(bytes->size() / 4);
    std::memcpy(words.data(), bytes->data(), bytes->size());
    if (words[0] != kSpirvMagic) return std::nullopt; // damaged: recompile and overwrite
    return words;
}

void SpirvCache::store(const std::string& key, const std::vector<uint32_t>& spirv) const
{
    std::error_code error;
    fs::create_directories(m_directory, error);
    std::random_device random;
    fs::path temporary = pathFor(key).string() + ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(random());
    {
        std::ofstream out(temporary, std::ios::binary);
        out.write(reinterpret_cast<const char*>(spirv.data()), std::streamsize(spirv.size() * 4));
        if (!out) {
            fs::remove(temporary, error);
            return; // an unwritable cache only costs a recompile next time
        }
    }
    fs::rename(temporary, pathFor(key), error);
    if (error) fs::remove(temporary, error);
}

CompiledKernel compileKernelCached(const KernelSource& source, const SpirvCache& cache)
{
    CompiledKernel kernel;
    kernel.cacheKey = kernelCacheKey(source);
    if (auto cached = cache.load(kernel.cacheKey)) {
        kernel.spirv = std::move(*cached);
        kernel.fromCache = true;
        return kernel;
    }
    auto start = std::chrono::steady_clock::now();
    kernel.spirv = compileGlsl(source);
    kernel.compileSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cache.store(kernel.cacheKey, kernel.spirv);
    return kernel;
}

} // namespace vkrt
