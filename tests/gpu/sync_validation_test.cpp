// Every GPU test runs under the validation layer with synchronization
// validation on (gpu/VulkanContext.cpp), so a missing barrier between two
// dispatches fails the test that makes it. lavapipe runs commands in order
// and never shows such a race in an image; a GPU would. This checks the
// check: two writes to one buffer without a barrier are reported as a
// hazard, and the same writes with one are not.
#include "gpu/Buffer.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

std::vector<std::string> messagesFrom(size_t before)
{
    std::vector<std::string> all = gpu().validationMessages();
    return {all.begin() + std::min(before, all.size()), all.end()};
}

void fillTwice(const Buffer& buffer, bool barrier)
{
    gpu().submitAndWait([&](vk::CommandBuffer cmd) {
        cmd.fillBuffer(buffer.handle(), 0, VK_WHOLE_SIZE, 1u);
        if (barrier) {
            vk::MemoryBarrier between(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eTransferWrite);
            cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eTransfer, {}, between,
                                {}, {});
        }
        cmd.fillBuffer(buffer.handle(), 0, VK_WHOLE_SIZE, 2u);
    });
}

TEST(SyncValidation, AWriteAfterWriteWithoutABarrierIsReported)
{
    Buffer buffer(gpu(), 4096, vk::BufferUsageFlagBits::eTransferDst, MemoryUse::Device);
    size_t before = gpu().validationMessages().size();
    fillTwice(buffer, true);
    EXPECT_TRUE(messagesFrom(before).empty()) << messagesFrom(before).front();

    before = gpu().validationMessages().size();
    fillTwice(buffer, false);
    std::vector<std::string> messages = messagesFrom(before);
    // The ID is in the text (older layers) or put there by vkrt's log (newer ones).
    const bool reported = std::any_of(messages.begin(), messages.end(), [](const std::string& m) {
        return m.find("SYNC-HAZARD-WRITE-AFTER-WRITE") != std::string::npos;
    });
    EXPECT_TRUE(reported) << messages.size() << " messages" << (messages.empty() ? "" : ", the first: " + messages[0]);
}

} // namespace
} // namespace vkrt::test
