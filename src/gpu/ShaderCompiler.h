#pragma once
// GLSL -> SPIR-V through glslang's C++ API, with an include resolver rooted at
// the shader folder and an on-disk SPIR-V cache keyed by a hash of every
// shader source, the defines and the glslang version.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vkrt {

using Define = std::pair<std::string, std::string>; ///< name, value

/// What to compile: a kernel file below the shader root, plus its defines.
struct KernelSource {
    std::filesystem::path shaderRoot;
    std::string entryFile; ///< relative to shaderRoot, e.g. "kernels/render.comp"
    std::vector<Define> defines;
};

struct CompiledKernel {
    std::vector<uint32_t> spirv;
    std::string cacheKey; ///< hex hash identifying the variant
    bool fromCache = false;
    double compileSeconds = 0.0; ///< glslang time (0 on a cache hit)
};

/// The shader folder: $VKRT_SHADER_DIR, else the source tree's, else the installed one.
std::filesystem::path defaultShaderRoot();

/// "name=value name2" as shown in messages and `vkrt info`.
std::string describeDefines(const std::vector<Define>& defines);

/// Compiles with glslang; throws GpuError with file:line messages and the defines.
std::vector<uint32_t> compileGlsl(const KernelSource& source);

/// Byte offset of every member of every uniform, storage and push-constant
/// block as glslang lays it out, keyed "Block.member[0].field" as glslang names them.
std::vector<std::pair<std::string, int>> reflectBlockMemberOffsets(const KernelSource& source);

/// How many times compileGlsl ran in this process (tests check cache hits).
uint64_t glslangInvocationCount();

/// The glslang version compiled in, e.g. "12.0.0".
std::string glslangVersion();

/// On-disk SPIR-V store. Writes go to a unique temporary file that is renamed
/// into place, so concurrent processes never see a partial file.
class SpirvCache {
public:
    explicit SpirvCache(std::filesystem::path directory);
    /// $VKRT_CACHE_DIR, else $XDG_CACHE_HOME/vkrt/spirv, else ~/.cache/vkrt/spirv.
    static std::filesystem::path defaultDirectory();

    std::optional<std::vector<uint32_t>> load(const std::string& key) const;
    void store(const std::string& key, const std::vector<uint32_t>& spirv) const;
    const std::filesystem::path& directory() const { return m_directory; }

private:
    std::filesystem::path m_directory;
    std::filesystem::path pathFor(const std::string& key) const;
};

/// Key of a variant: hash of all files below the shader root, entry, defines, glslang version.
std::string kernelCacheKey(const KernelSource& source);

/// The cached SPIR-V for `source` if present, else compiles and stores it.
CompiledKernel compileKernelCached(const KernelSource& source, const SpirvCache& cache);

} // namespace vkrt
