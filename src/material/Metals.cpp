#include "material/Metals.h"

namespace vkrt {
namespace {

// Source: the measured spectra Mitsuba ships as data/ior/<name>.{eta,k}.spd (Palik's "Handbook of Optical
// Constants of Solids" and Weaver's "Physics Data" tables), the same set Mitsuba 3's `conductor` and
// `roughconductor` use for their `material` names. In RGB mode Mitsuba 3 projects each spectrum onto
// linear sRGB (spectrum_list_to_srgb); the numbers below are that projection as published in Tungsten's
// ComplexIorData.hpp (rounded to 4 decimals), which was generated from Mitsuba's spectra. They are not
// re-derived here: expect differences of up to ~1 % from Mitsuba 3's own conversion.
// "none" is Mitsuba's default: eta = 0, k = 1, a perfect mirror (F = 1 at every angle).
constexpr Metal kMetals[] = {
    {"none", {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}},
    {"Ag", {0.1553, 0.1167, 0.1384}, {4.8283, 3.1222, 2.1470}},
    {"Al", {1.6575, 0.8804, 0.5212}, {9.2239, 6.2695, 4.8370}},
    {"Au", {0.1431, 0.3750, 1.4425}, {3.9832, 2.3857, 1.6032}},
    {"Cr", {4.3697, 2.9167, 1.6547}, {5.2064, 4.2314, 3.7549}},
    {"Cu", {0.2004, 0.9240, 1.1022}, {3.9129, 2.4528, 2.1422}},
    {"Hg", {2.3989, 1.4400, 0.9096}, {6.3276, 4.3719, 3.4218}},
    {"Ir", {3.0864, 2.0822, 1.6179}, {5.5922, 4.0672, 3.2673}},
    {"Li", {0.2658, 0.1956, 0.2209}, {3.5402, 2.3111, 1.6686}},
    {"Mo", {4.4837, 3.5255, 2.7761}, {4.1111, 3.4209, 3.1506}},
    {"Rh", {2.5858, 1.8602, 1.5544}, {6.7823, 4.7030, 3.9761}},
    {"W", {4.3707, 3.3003, 2.9983}, {3.5007, 2.6049, 2.2732}},
};

} // namespace

const Metal* findMetal(std::string_view name)
{
    for (const Metal& metal : kMetals)
        if (metal.name == name) return &metal;
    return nullptr;
}

std::vector<std::string> metalNames()
{
    std::vector<std::string> names;
    for (const Metal& metal : kMetals) names.emplace_back(metal.name);
    return names;
}

} // namespace vkrt
