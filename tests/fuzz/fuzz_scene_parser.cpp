// libFuzzer target for the scene parser: the bytes are a scene file's text.
// Any outcome but a Scene or an InputError (SceneError included) is a bug.
#include "scene/SceneParser.h"
#include "util/Error.h"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    try {
        vkrt::parseSceneString(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.toml");
    } catch (const vkrt::InputError&) {
        // the expected outcome for almost every input
    }
    return 0;
}
