// --max-texture-chunk-bytes, the same for every command that makes a renderer.
#include "app/Commands.h"

#include <CLI/CLI.hpp>

namespace vkrt {

void addTextureChunkOption(CLI::App& command, uint64_t& bytes)
{
    // At least 8 bytes: a chunk holds whole half-float texels (two words).
    command
        .add_option("--max-texture-chunk-bytes", bytes,
                    "Split the scene's texels into storage buffers of at most this many bytes (test hook; default: "
                    "the device's maxStorageBufferRange)")
        ->check(CLI::Range(uint64_t(8), uint64_t(1) << 40))
        ->group("");
}

} // namespace vkrt
