#pragma once
// Named conductors for `type = "conductor"`, `metal = "Au"`: complex indices of refraction per RGB channel.
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace vkrt {

/// Complex index of refraction eta + i k of a named conductor, per linear sRGB channel.
struct Metal {
    std::string_view name;
    std::array<double, 3> eta;
    std::array<double, 3> k;
};

/// The named conductor, or nullptr when there is none of that name (names are case-sensitive, as Mitsuba's).
const Metal* findMetal(std::string_view name);

/// Every name findMetal knows, in table order (for "did you mean" messages and docs).
std::vector<std::string> metalNames();

} // namespace vkrt
