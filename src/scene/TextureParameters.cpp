#include "scene/TextureParameters.h"

#include "util/KernelLimits.h"

#include <array>
#include <cmath>
#include <string_view>

namespace vkrt {
namespace {

constexpr std::array<std::string_view, 5> colorTextureKeys{"texture", "scale", "linear", "wrap", "filter"};
constexpr std::array<std::string_view, 6> scalarTextureKeys{"texture", "scale", "linear", "wrap", "filter", "channel"};
constexpr std::array<std::string_view, 5> normalMapKeys{"texture", "scale", "wrap", "filter", "strength"};
constexpr std::array<std::string_view, 4> vectorTextureKeys{"texture", "scale", "wrap", "filter"};

constexpr std::array<EnumName<TextureWrap>, 3> wrapModes{
    {{"repeat", TextureWrap::Repeat}, {"clamp", TextureWrap::Clamp}, {"mirror", TextureWrap::Mirror}}};
constexpr std::array<EnumName<uint32_t>, 4> channels{{{"r", 0}, {"g", 1}, {"b", 2}, {"a", 3}}};
// "nearest": no interpolation at all, the nearest texel of the nearest mip
// level (glTF's NEAREST and NEAREST_MIPMAP_NEAREST); "linear": the default.
constexpr TextureFilter kNearest{true, true, TextureFilter::Mip::Nearest};
constexpr std::array<EnumName<TextureFilter>, 2> filters{{{"linear", TextureFilter{}}, {"nearest", kNearest}}};

TextureWrap readWrapMode(const Field& field) { return readChoice(field, "wrap mode", wrapModes).value; }

/// `wrap`: one mode for both axes, or [u, v].
std::pair<TextureWrap, TextureWrap> readWrap(const Field& field)
{
    if (!field.node().is_array()) {
        const TextureWrap both = readWrapMode(field);
        return {both, both};
    }
    const toml::array& pair = *field.node().as_array();
    if (pair.size() != 2)
        field.fail("expected a wrap mode or a pair [u, v] of them, got " + std::to_string(pair.size()) + " element(s)");
    return {readWrapMode(field.element(0, *pair.get(0))), readWrapMode(field.element(1, *pair.get(1)))};
}

/// `scale`: one number or [su, sv], finite and non-zero (a negative one mirrors).
glm::dvec2 readUvScale(const Field& field)
{
    auto component = [](const Field& f) {
        const double value = readNumber(f);
        if (value == 0.0) f.fail("must not be zero (every point would read one texel)");
        if (std::abs(value) > kMaxKernelMagnitude)
            f.fail("must be at most " + formatNumber(kMaxKernelMagnitude) +
                   " in magnitude (the kernel's float32 texture coordinates), got " + formatNumber(value));
        return value;
    };
    if (!field.node().is_array()) return glm::dvec2(component(field));
    const toml::array& pair = *field.node().as_array();
    if (pair.size() != 2)
        field.fail("expected a number or a pair [su, sv], got " + std::to_string(pair.size()) + " element(s)");
    return {component(field.element(0, *pair.get(0))), component(field.element(1, *pair.get(1)))};
}

std::span<const std::string_view> keysFor(TextureUse use)
{
    switch (use) {
    case TextureUse::Color: return colorTextureKeys;
    case TextureUse::Scalar: return scalarTextureKeys;
    case TextureUse::NormalMap: return normalMapKeys;
    case TextureUse::Vector: return vectorTextureKeys;
    }
    return colorTextureKeys;
}

} // namespace

bool isTextureTable(const Field& field) { return field.node().is_table(); }

MaterialTexture readTextureTable(const Field& field, TextureUse use, TextureAtlas& atlas, double* normalStrength)
{
    const TableField table(field);
    table.rejectUnknownKeys(keysFor(use));
    const Field file = table.require("texture");
    TextureRequest request;
    request.file = readPath(file);
    request.linear =
        use == TextureUse::NormalMap || use == TextureUse::Vector || readOr(table, "linear", false, readBool);
    std::tie(request.wrapU, request.wrapV) =
        readOr(table, "wrap", std::make_pair(TextureWrap::Repeat, TextureWrap::Repeat), readWrap);
    request.filter =
        readOr(table, "filter", TextureFilter{}, [](const Field& f) { return readChoice(f, "filter", filters).value; });
    MaterialTexture texture;
    texture.scale = readOr(table, "scale", glm::dvec2(1.0), readUvScale);
    texture.channel =
        readOr(table, "channel", 0u, [](const Field& f) { return readChoice(f, "channel", channels).value; });
    if (normalStrength) *normalStrength = readOr(table, "strength", 1.0, readNonNegative);
    texture.record = atlas.add(request, file.location());
    return texture;
}

} // namespace vkrt
