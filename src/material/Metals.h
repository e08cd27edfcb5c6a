#pragma once
// Named metals for `type = "conductor"`, `metal = "Au"`: complex indices of
// refraction eta + i k per RGB channel.
#include "scene/Scene.h"

#include <optional>
#include <string_view>
#include <vector>

namespace vkrt {

struct ConductorIor {
    Color eta;
    Color k;
};

/// The metal called `name` (case-sensitive chemical symbol), if vkrt knows it.
std::optional<ConductorIor> findMetal(std::string_view name);

/// Every known name, for messages (did-you-mean, the list of choices).
const std::vector<std::string_view>& metalNames();

} // namespace vkrt
