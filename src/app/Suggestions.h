#pragma once
// "Did you mean" for the command line, as the scene parser has for keys: a
// misspelt subcommand (`vkrt rendr`) or option (`--samples 16`) gets the
// nearest name, or the one other renderers' users reach for.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace vkrt {

/// For a command line CLI11 refused: "did you mean `render`?" or "did you
/// mean --spp?" naming the first word it could be; nothing when no name is
/// close. `app` is the parsed application (its subcommands and their options).
std::optional<std::string> commandLineSuggestion(CLI::App& app, int argc, const char* const* argv);

} // namespace vkrt
