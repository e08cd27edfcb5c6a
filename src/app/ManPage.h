#pragma once
// `vkrt man`: the manual page (roff), written from the same CLI11 definitions
// that parse the command line, so that it cannot drift from them. The build
// writes it to build/vkrt.1 and `cmake --install` installs it (man 1 vkrt).
#include <CLI/CLI.hpp>

#include <string>

namespace vkrt {

/// The page for `app` and every subcommand: synopsis, each option with its
/// description, and pointers to the docs.
std::string manPage(const CLI::App& app);

} // namespace vkrt
