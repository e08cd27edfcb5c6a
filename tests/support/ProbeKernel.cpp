#include "support/ProbeKernel.h"

#include "support/ProbeBuffers.h"

namespace vkrt::test {

std::vector<float> runProbe(const std::string& kernel, const std::vector<float>& input, size_t outputFloats,
                            uint32_t invocations, const std::vector<Define>& defines)
{
    return runProbeWithBuffers(kernel, input, outputFloats, invocations, {}, defines);
}

} // namespace vkrt::test
