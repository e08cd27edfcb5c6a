// vkrt-make-mesh: writes a procedural test mesh (for benchmarks and scenes).
//   vkrt-make-mesh sphere|soup|grid TRIANGLES OUT.(ply|obj) [--ascii]
// sphere: a UV sphere of radius 1 with radial vertex normals; soup: small
// random triangles in the unit cube (seed 1); grid: a quad grid on z = 0.
// The triangle count is a lower bound (the shapes round it up).
#include "mesh/Procedural.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>

int main(int argc, char** argv)
{
    CLI::App app{"Writes a procedural mesh file"};
    std::string shape, out;
    uint32_t triangles = 0;
    bool ascii = false;
    app.add_option("shape", shape, "sphere, soup or grid")->required()->check(CLI::IsMember({"sphere", "soup", "grid"}));
    app.add_option("triangles", triangles, "Triangle count (at least)")->required()->check(CLI::Range(1u, 100000000u));
    app.add_option("out", out, "Output file (.ply or .obj)")->required();
    app.add_flag("--ascii", ascii, "ASCII PLY instead of binary");
    CLI11_PARSE(app, argc, argv);
    try {
        vkrt::MeshData mesh;
        if (shape == "sphere") mesh = vkrt::makeUvSphere(triangles, glm::vec3(0.0f), 1.0f);
        else if (shape == "soup") mesh = vkrt::makeRandomSoup(triangles, 1);
        else mesh = vkrt::makeGrid(uint32_t(std::ceil(std::sqrt(triangles / 2.0))));
        const bool obj = out.size() >= 4 && out.substr(out.size() - 4) == ".obj";
        if (obj) vkrt::writeObj(mesh, out);
        else vkrt::writePly(mesh, out, !ascii);
        std::printf("%s: %zu triangles, %zu vertices\n", out.c_str(), mesh.triangles.size(), mesh.positions.size());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vkrt-make-mesh: %s\n", e.what());
        return 2;
    }
    return 0;
}
