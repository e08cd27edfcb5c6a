#pragma once
// Invalid TOML documents on which toml++ 3.3 (Debian 12) trips its own debug
// assertions or reaches a __builtin_unreachable (fixed upstream after 3.3).
// The compiled library vkrt links reports each as a parse error; the scene and
// suite tests check that this stays so.
#include <ostream>
#include <string>
#include <vector>

namespace vkrt {

struct TomlTrap {
    std::string name;
    std::string text; ///< one line, without its newline
};

/// gtest prints the name, not the (partly invalid) bytes.
inline void PrintTo(const TomlTrap& trap, std::ostream* out) { *out << trap.name; }

inline const std::vector<TomlTrap> kTomlTraps = {
    {"TableNameStartsWithDot", "[."},
    {"ArrayClosedByBrace", "v=[}"},
    {"DateTimeWithoutHour", "A=1979-05-27T:"},
    {"LoneNonAsciiLetterUtf8", "\xC3\xA9"}, // 'é' in UTF-8: the __builtin_unreachable
    {"LoneInvalidByte", "\xE9"},            // 'é' in Latin-1: not UTF-8 at all
    {"NonAsciiKeyUtf8", "\xC3\xA9 = 1"},
    {"InvalidByteInKey", "\xE9 = 1"},
};

} // namespace vkrt
