#pragma once
// Runs small GLSL test kernels (tests/gpu/kernels/*.comp) that exercise the
// real shader library on the GPU: binding 0 is a float input array, binding 1
// a float output array, and the push constant is the invocation count.
#include "gpu/ShaderCompiler.h"

#include <string>
#include <vector>

namespace vkrt::test {

/// Dispatches `invocations` invocations (64 per workgroup, 1D) of
/// tests/gpu/kernels/<kernel>.comp and returns `outputFloats` floats.
std::vector<float> runProbe(const std::string& kernel, const std::vector<float>& input, size_t outputFloats,
                            uint32_t invocations, const std::vector<Define>& defines = {});

} // namespace vkrt::test
