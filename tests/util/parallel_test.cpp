// forEachInParallel (src/util/Parallel.h): every item once, and the error a
// serial loop over the items would have reported first.
#include "util/Parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace vkrt::test {
namespace {

TEST(ForEachInParallel, RunsEveryItemOnce)
{
    std::vector<std::atomic<int>> runs(1000);
    forEachInParallel(runs.size(), [&](size_t i) { ++runs[i]; });
    for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].load(), 1) << "item " << i;
    forEachInParallel(0, [](size_t) { FAIL() << "no item to run"; });
}

TEST(ForEachInParallel, RethrowsTheLowestFailingItemsErrorAfterRunningThemAll)
{
    std::atomic<int> ran{0};
    try {
        forEachInParallel(64, [&](size_t i) {
            ++ran;
            if (i % 10 == 7) throw std::runtime_error("item " + std::to_string(i));
        });
        FAIL() << "nothing thrown";
    } catch (const std::runtime_error& error) {
        EXPECT_STREQ(error.what(), "item 7");
    }
    EXPECT_EQ(ran.load(), 64);
}

} // namespace
} // namespace vkrt::test
