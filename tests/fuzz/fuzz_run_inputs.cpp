// libFuzzer target for the inputs besides scenes and meshes: the first byte
// chooses what the rest is (0 an image file: Radiance .hdr, EXR, PNG or JPEG,
// decoded as a texture; 1 a --baseline file; 2 a --flakes/--skips file; 3 a
// regression suite manifest). Any outcome but a result or an InputError is a
// bug, and so is a run that does not end (libFuzzer's -timeout).
#include "regress/Expectations.h"
#include "regress/Suite.h"
#include "texture/TextureImage.h"
#include "util/Error.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include <unistd.h>

namespace {

/// The readers of baseline files and manifests take a path: one file per process, rewritten per input.
std::filesystem::path inputFile(const char* extension)
{
    return std::filesystem::temp_directory_path() / ("vkrt-fuzz-" + std::to_string(getpid()) + extension);
}

void writeFile(const std::filesystem::path& path, std::span<const uint8_t> bytes)
{
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size == 0) return 0;
    const std::span<const uint8_t> bytes(data + 1, size - 1);
    try {
        switch (data[0] % 4) {
        case 0: vkrt::decodeTextureImage(bytes, "fuzz-image", true); break;
        case 1: {
            const auto path = inputFile(".txt");
            writeFile(path, bytes);
            vkrt::readBaseline(path);
            break;
        }
        case 2: {
            const auto path = inputFile(".txt");
            writeFile(path, bytes);
            vkrt::readNamePatterns(path, "--skips");
            break;
        }
        default: {
            const auto path = inputFile(".toml");
            writeFile(path, bytes);
            vkrt::readRegressionSuite(path);
            break;
        }
        }
    } catch (const vkrt::InputError&) {
        // the expected outcome for almost every input
    }
    return 0;
}
