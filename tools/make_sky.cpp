// vkrt-make-sky: writes the six EXR faces (px nx py ny pz nz .exr) of an
// analytic sky cubemap for scene files' [background.cubemap], or with
// --latlong WIDTH one lat-long map (sky.exr) for [background.environment].
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
    uint32_t latLongWidth = 0;
    vkrt::SkyParameters sky;
    // --help shows each option's default (the values above and SkyParameters').
    app.option_defaults()->always_capture_default();
    app.add_option("directory", directory, "Output folder (created if missing)")->required();
    app.add_option("--size", size, "Face width and height in texels")->check(CLI::Range(1u, 4096u));
    app.add_option("--sun-elevation", sky.sunElevationDegrees, "Degrees above the horizon")
        ->check(CLI::Range(-90.0, 90.0));
    app.add_option("--sun-azimuth", sky.sunAzimuthDegrees, "Degrees from +z towards +x")
        ->check(CLI::Range(-360.0, 360.0));
    app.add_option("--sun-radiance", sky.sunRadiance, "Radiance of the sun disk")->check(CLI::Range(0.0, 1e30));
    app.add_option("--sun-radius", sky.sunAngularRadiusDegrees, "Angular radius of the sun in degrees")
        ->check(CLI::Range(0.01, 45.0));
    app.add_option("--latlong", latLongWidth,
                   "Write one lat-long map DIRECTORY/sky.exr of this width (height width/2 + 1) instead of faces")
        ->check(CLI::Range(2u, 16384u));
    CLI11_PARSE(app, argc, argv);

    try {
        std::filesystem::create_directories(directory);
        vkrt::Metadata metadata{{"generator", std::string("vkrt-make-sky")}};
        if (latLongWidth > 0) {
            const vkrt::Image map = vkrt::renderSkyLatLong(sky, latLongWidth);
            vkrt::writeExr(std::filesystem::path(directory) / "sky.exr", map, metadata);
            std::printf("wrote %s/sky.exr (%ux%u)\n", directory.c_str(), map.width, map.height);
            return 0;
        }
        auto faces = vkrt::renderSkyFaces(sky, size);
        const char* names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
        for (int i = 0; i < 6; ++i)
            vkrt::writeExr(std::filesystem::path(directory) / (std::string(names[i]) + ".exr"), faces[i], metadata);
        std::printf("wrote %s/{px,nx,py,ny,pz,nz}.exr (%ux%u)\n", directory.c_str(), size, size);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vkrt-make-sky: error: %s\n", e.what());
        return 2;
    }
    return 0;
}
