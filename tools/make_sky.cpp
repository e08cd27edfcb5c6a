// vkrt-make-sky: writes the six EXR faces (px nx py ny pz nz .exr) of an
// analytic sky cubemap for scene files' [background.cubemap].
#include "io/ExrFile.h"
#include "render/Sky.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv)
{
    CLI::App app("Write an analytic sky (gradient plus sun) as six cubemap faces", "vkrt-make-sky");
    std::string directory;
    uint32_t size = 128;
    vkrt::SkyParameters sky;
    app.add_option("directory", directory, "Output folder (created if missing)")->required();
    app.add_option("--size", size, "Face width and height in texels")->check(CLI::Range(1u, 4096u));
    app.add_option("--sun-elevation", sky.sunElevationDegrees, "Degrees above the horizon")
        ->check(CLI::Range(-90.0, 90.0));
    app.add_option("--sun-azimuth", sky.sunAzimuthDegrees, "Degrees from +z towards +x")
        ->check(CLI::Range(-360.0, 360.0));
    app.add_option("--sun-radiance", sky.sunRadiance, "Radiance of the sun disk")->check(CLI::Range(0.0, 1e30));
    app.add_option("--sun-radius", sky.sunAngularRadiusDegrees, "Angular radius of the sun in degrees")
        ->check(CLI::Range(0.01, 45.0));
    CLI11_PARSE(app, argc, argv);

    try {
        std::filesystem::create_directories(directory);
        auto faces = vkrt::renderSkyFaces(sky, size);
        const char* names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
        vkrt::Metadata metadata{{"generator", std::string("vkrt-make-sky")}};
        for (int i = 0; i < 6; ++i)
            vkrt::writeExr(std::filesystem::path(directory) / (std::string(names[i]) + ".exr"), faces[i], metadata);
        std::printf("wrote %s/{px,nx,py,ny,pz,nz}.exr (%ux%u)\n", directory.c_str(), size, size);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vkrt-make-sky: error: %s\n", e.what());
        return 2;
    }
    return 0;
}
