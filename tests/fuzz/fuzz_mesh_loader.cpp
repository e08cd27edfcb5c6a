// libFuzzer target for the mesh path (loadMeshFile, normals, BVH build; a glTF
// file read as a whole scene: its cameras, lights and material extensions
// too): the first byte picks the format, the rest is the file. Any outcome but a MeshData or an InputError (another
// exception, a crash, a sanitizer report, a hang) is a bug. tools/fuzz.sh runs it. The default MeshLoadOptions apply: a
// glTF's buffer or image URI, or an OBJ's mtllib, that leaves the fuzzer's folder is refused (ReferencePolicy.h), so no
// input makes the target read other files; glTF node depth, JSON nesting, node
// counts, triangles after instancing and accessor data are bounded before
// assimp (FileMaterials.h).
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/GltfScene.h"
#include "util/Error.h"

#include <unistd.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

const std::filesystem::path& fuzzDir()
{
    // One directory per process: libFuzzer's -jobs/-workers run several at once.
    static const std::filesystem::path dir = [] {
        auto path = std::filesystem::temp_directory_path() / ("vkrt-fuzz-mesh-" + std::to_string(getpid()));
        std::filesystem::create_directories(path);
        return path;
    }();
    return dir;
}

} // namespace

// Assimp 5.2 leaks the mesh it was building when its PLY reader throws halfway
// (e.g. on a malformed number), inside libassimp where we cannot free it; the
// leak checker (ASan builds, the fuzzer) must not count that against vkrt.
// Leaks with any other origin are still reported.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

// No texture cache: a glTF input's images would fill the user's cache folder.
extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    setenv("VKRT_TEXTURE_CACHE_DIR", "off", 1);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size == 0) return 0;
    static const std::array<const char*, 4> extensions{".obj", ".ply", ".gltf", ".glb"};
    const std::filesystem::path file = fuzzDir() / (std::string("input") + extensions[data[0] % extensions.size()]);
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
    }
    try {
        // The whole mesh path of a scene: load, smooth normals, BVH, leaf
        // order; a glTF file as a whole scene (its camera, lights, materials).
        // A glTF file both ways: as a scene (instances kept) and as one mesh (instances flattened).
        if (vkrt::isGltfPath(file)) vkrt::parseGltfScene(file.string());
        vkrt::makeMeshGeometry(file, vkrt::NormalMode::Smooth);
    } catch (const vkrt::InputError&) {
        // the expected outcome for almost every input
    }
    return 0;
}
