// libFuzzer target for the scene parser: the bytes are a scene file's text.
// Any outcome but a Scene or an InputError (SceneError included) is a bug.
#include "scene/SceneParser.h"
#include "util/Error.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

// A scene may name a broken mesh file: assimp leaks the mesh it was building
// when its PLY reader fails (a Debian 12 assimp defect; see fuzz_mesh_loader.cpp).
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

// No texture cache: the inputs' images would fill the user's cache folder.
extern "C" int LLVMFuzzerInitialize(int*, char***)
{
    setenv("VKRT_TEXTURE_CACHE_DIR", "off", 1);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    try {
        vkrt::parseSceneString(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.toml");
    } catch (const vkrt::InputError&) {
        // the expected outcome for almost every input
    }
    return 0;
}
