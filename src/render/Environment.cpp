#include "render/Environment.h"

#include "io/PngFile.h"
#include "util/Error.h"

namespace vkrt {

std::array<Image, 6> loadCubemapFaces(const Cubemap& cubemap)
{
    static const char* const kFaceKeys[6] = {"px", "nx", "py", "ny", "pz", "nz"};
    std::array<Image, 6> faces;
    for (int i = 0; i < 6; ++i) {
        std::string label = cubemap.where.str() + ": background.cubemap." + kFaceKeys[i] + ": ";
        try {
            faces[i] = readRgbImage(cubemap.facePaths[i]);
        } catch (const InputError& e) {
            throw InputError(label + e.what());
        }
        if (faces[i].width != faces[i].height || faces[i].width == 0)
            throw InputError(label + cubemap.facePaths[i] + ": a cube face must be square, got " +
                             std::to_string(faces[i].width) + "x" + std::to_string(faces[i].height));
        if (faces[i].width != faces[0].width)
            throw InputError(label + cubemap.facePaths[i] + ": all faces must have the same size (" +
                             std::to_string(faces[0].width) + " for px), got " + std::to_string(faces[i].width));
        for (float v : faces[i].rgb)
            if (!std::isfinite(v) || v < 0.0f)
                throw InputError(label + cubemap.facePaths[i] + ": contains a negative or non-finite value");
    }
    return faces;
}

} // namespace vkrt
