#pragma once
// A regression suite manifest (TOML, docs/regress.md): cases, each a scene
// rendered at a fixed size, spp and seed and tested against a reference mean
// and variance.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

enum class ReferenceSource { Mitsuba, Vkrt };

struct RegressionCase {
    std::string name;
    std::filesystem::path scene;
    std::filesystem::path referenceDir; ///< holds mean.exr and variance.exr
    ReferenceSource source = ReferenceSource::Vkrt;
    uint64_t referenceSpp = 0; ///< samples behind the reference mean
    uint32_t spp = 64;
    std::optional<uint32_t> width, height;
    double baselineSeconds = 0.0; ///< 0: no timing check
    uint64_t maxRejected = 0;     ///< non-finite samples tolerated (known bugs only)
    uint32_t shards = 1;          ///< >1: rendered as that many shards, merged (docs/farm.md)
};

struct RegressionSuite {
    std::filesystem::path path;
    double alpha = 0.01;
    double pooledAlpha = 0.001;
    double minPass = 0.9975;
    double maxSlowdown = 3.0;
    uint32_t seed = 1;
    std::vector<RegressionCase> cases;
};

/// A case name's longest (what reports echo of any value is cut there too).
inline constexpr size_t kMaxCaseNameBytes = 96;
/// The characters of a case name: letters, digits and `._/+-` (reports write names unescaped).
bool isCaseNameCharacter(char c);

/// Parses and checks a manifest; paths are resolved against its folder.
/// Errors are InputError "file:line:column: ...".
RegressionSuite readRegressionSuite(const std::filesystem::path& path);

} // namespace vkrt
