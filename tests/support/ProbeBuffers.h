#pragma once
// runProbe (support/ProbeKernel.h) with extra storage buffers bound beside the
// probe's input (binding 0) and output (binding 1), e.g. the texture buffers.
#include "gpu/ShaderCompiler.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vkrt::test {

/// One extra read-only storage buffer: its binding index and contents.
struct ProbeBuffer {
    uint32_t binding;
    std::vector<std::byte> bytes;
};

/// Bytes of a vector of GPU records, for ProbeBuffer::bytes.
template <typename T>
std::vector<std::byte> probeBytes(const std::vector<T>& records)
{
    auto bytes = std::as_bytes(std::span(records));
    return {bytes.begin(), bytes.end()};
}

/// Dispatches tests/gpu/kernels/<kernel>.comp as runProbe does, with `buffers` bound too.
std::vector<float> runProbeWithBuffers(const std::string& kernel, const std::vector<float>& input,
                                       size_t outputFloats, uint32_t invocations,
                                       const std::vector<ProbeBuffer>& buffers,
                                       const std::vector<Define>& defines = {});

} // namespace vkrt::test
