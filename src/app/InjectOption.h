#pragma once
// --inject FAULT, the same for every command that renders: a SPIR-V fault
// (gpu/SpirvFault.h) every kernel of the process and of its children runs with.
#include <string>

namespace CLI {
class App;
}

namespace vkrt {

/// Adds `--inject FAULT` to a command, checked as it is parsed, writing the spec to `fault`.
void addInjectOption(CLI::App& command, std::string& fault);

/// Sets $VKRT_INJECT_FAULT to `fault` for this process and the ones it starts
/// (ComputeKernel reads it there) and returns it; with no --inject, returns
/// the variable's own value, checked (InputError naming it), or "" if unset.
std::string applyInjectOption(const std::string& fault);

} // namespace vkrt
