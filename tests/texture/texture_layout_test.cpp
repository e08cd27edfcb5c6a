// shared/TextureTypes.h's TextureRecord as glslang lays it out in a kernel
// that includes lib/texture.glsl, against the C++ offsets (no GPU needed).
#include "gpu/ShaderCompiler.h"
#include "shared/TextureTypes.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <map>

namespace vkrt::test {
namespace {

TEST(TextureLayout, RecordOffsetsMatchGlslangReflection)
{
    KernelSource source{defaultShaderRoot(), "../tests/gpu/kernels/texture_probe.comp", {}};
    std::map<std::string, int> offsets;
    for (const auto& [name, offset] : reflectBlockMemberOffsets(source)) offsets[name] = offset;
    const std::pair<const char*, size_t> members[] = {
        {"textureRecords[0].width", offsetof(gpu::TextureRecord, width)},
        {"textureRecords[0].height", offsetof(gpu::TextureRecord, height)},
        {"textureRecords[0].levels", offsetof(gpu::TextureRecord, levels)},
        {"textureRecords[0].format", offsetof(gpu::TextureRecord, format)},
        {"textureRecords[0].wrapU", offsetof(gpu::TextureRecord, wrapU)},
        {"textureRecords[0].wrapV", offsetof(gpu::TextureRecord, wrapV)},
        {"textureRecords[0].filters", offsetof(gpu::TextureRecord, filters)},
        {"textureRecords[0].levelOffset", offsetof(gpu::TextureRecord, levelOffset)},
    };
    std::string names;
    for (const auto& [name, offset] : offsets) names += name + "@" + std::to_string(offset) + " ";
    for (const auto& [name, offset] : members) {
        auto it = offsets.find(name);
        ASSERT_NE(it, offsets.end()) << name << " not reflected; glslang reported: " << names;
        EXPECT_EQ(size_t(it->second), offset) << name;
    }
    // The array runs to the end of the struct: no tail padding either side.
    EXPECT_EQ(offsets.at("textureRecords[0].levelOffset") + 4 * int(gpu::TEXTURE_MAX_LEVELS),
              int(sizeof(gpu::TextureRecord)));
}

} // namespace
} // namespace vkrt::test
