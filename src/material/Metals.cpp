#include "material/Metals.h"

#include <array>

namespace vkrt {
namespace {

struct NamedMetal {
    std::string_view name;
    ConductorIor ior;
};

// RGB reductions of measured spectral indices (the values Mitsuba 0.5 and
// pbrt-based renderers ship for their named conductors, from the data of
// Palik's Handbook of Optical Constants of Solids). tools/to_mitsuba.py
// passes these numbers to Mitsuba, so validation compares like with like.
const std::array<NamedMetal, 5> kMetals{{
    {"Ag", {{0.155265, 0.116723, 0.138342}, {4.82835, 3.12225, 2.14696}}},
    {"Al", {{1.65746, 0.880369, 0.521229}, {9.22387, 6.26952, 4.837}}},
    {"Au", {{0.143119, 0.374957, 1.44248}, {3.98316, 2.38572, 1.60322}}},
    {"Cr", {{4.36968, 2.9167, 1.6547}, {5.20643, 4.23136, 3.75495}}},
    {"Cu", {{0.200438, 0.924033, 1.10221}, {3.91295, 2.45285, 2.14219}}},
}};

} // namespace

std::optional<ConductorIor> findMetal(std::string_view name)
{
    for (const NamedMetal& metal : kMetals)
        if (metal.name == name) return metal.ior;
    return std::nullopt;
}

const std::vector<std::string_view>& metalNames()
{
    static const std::vector<std::string_view> names = [] {
        std::vector<std::string_view> list;
        for (const NamedMetal& metal : kMetals) list.push_back(metal.name);
        return list;
    }();
    return names;
}

} // namespace vkrt
