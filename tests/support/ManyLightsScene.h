// The scene the loop-budget tests share (render/loop_budget_test.cpp on a
// device, render/loop_cap_rule_test.cpp without one).
#pragma once

#include <string>

namespace vkrt::test {

/// A lit plane seen by the camera, `spheres` small spheres beside it and
/// `lights` point lights of intensity `intensity` at one position: each pixel
/// of the plane runs one shadow query over every primitive per light.
inline std::string manyLightsScene(int spheres, int lights, double intensity)
{
    std::string text = "[render]\nmax_depth = 1\n[camera]\neye = [0, 2, 4]\ntarget = [0, 0, 0]\nfov = 40\n"
                       "width = 8\nheight = 8\n[materials.m]\ntype = \"lambert\"\n"
                       "[[objects]]\nshape = \"plane\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\nmaterial = \"m\"\n";
    // Appended piece by piece: GCC 14 reports a false -Warray-bounds at -O2 in
    // the inlined `std::string&& + "..."`.
    for (int i = 0; i < spheres; ++i) {
        text += "[[objects]]\nshape = \"sphere\"\ncenter = [";
        text += std::to_string(100 + i);
        text += ", 0, -50]\nradius = 0.1\nmaterial = \"m\"\n";
    }
    for (int i = 0; i < lights; ++i)
        text +=
            "[[lights]]\ntype = \"point\"\nposition = [0.5, 3, 0.5]\nintensity = " + std::to_string(intensity) + "\n";
    return text;
}

} // namespace vkrt::test
