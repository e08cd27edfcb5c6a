// Value readers the scene format shares (scene/SceneValues.h).
#include "scene/SceneValues.h"

#include "scene/SceneOverrides.h"

#include <glm/gtc/matrix_transform.hpp>
#include <limits>

namespace vkrt {

namespace fs = std::filesystem;

double readIor(const Field& field)
{
    const double value = readNumber(field);
    if (value < 1) field.fail("must be >= 1, got " + formatNumber(value));
    if (value > SceneLimits::maxIor)
        field.fail("must be <= " + formatNumber(SceneLimits::maxIor) + ", got " + formatNumber(value));
    return value;
}

glm::dmat4 readRotation(const Field& field)
{
    static constexpr std::array<std::string_view, 2> rotateKeys{"axis", "angle"};
    const TableField table(field);
    table.rejectUnknownKeys(rotateKeys);
    const Field axisField = table.require("axis");
    const std::optional<glm::dvec3> axis = normalized(readVector(axisField));
    if (!axis) axisField.fail("must not be zero-length");
    const double angle = readNumber(table.require("angle"));
    return glm::rotate(glm::dmat4(1.0), glm::radians(angle), *axis);
}

std::array<glm::dvec3, 3> readVertices(const Field& field) { return readTriple(field, "points", readVector); }

namespace {

double checkChannel(const Field& field, double value, ColorRange range)
{
    if (range == ColorRange::Unit && !(value >= 0 && value <= 1))
        field.fail("must be in [0, 1], got " + formatNumber(value));
    if (value < 0) field.fail("must be >= 0, got " + formatNumber(value));
    // Colours reach the GPU as they are, in 32-bit floats, where this would be
    // infinite. (Positions may exceed it: they are made camera-relative in
    // double precision first.)
    if (value > std::numeric_limits<float>::max())
        field.fail("must be at most 3.4e38 (the largest 32-bit float; vkrt renders with those), got " +
                   formatNumber(value));
    return value;
}

} // namespace

/// A colour is three channels or one number meaning grey.
Color readColor(const Field& field, ColorRange range)
{
    const auto channel = [range](const Field& f) { return checkChannel(f, readNumber(f), range); };
    if (field.node().is_number()) return Color(channel(field));
    if (!field.node().is_array())
        field.fail("expected a colour (a number or an array of 3 numbers), got " + describeType(field.node()));
    const auto c = readTriple(field, "numbers", channel);
    return {c[0], c[1], c[2]};
}

Color readUnitColor(const Field& field) { return readColor(field, ColorRange::Unit); }
Color readRadiance(const Field& field) { return readColor(field, ColorRange::NonNegative); }

void checkRegularFile(const Field& field, const fs::path& path)
{
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) field.fail("file " + quote(path.string()) + " does not exist");
    if (!fs::is_regular_file(status)) field.fail(quote(path.string()) + " is not a regular file");
}

} // namespace vkrt
