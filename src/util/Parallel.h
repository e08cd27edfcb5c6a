#pragma once
// Independent work items spread over the cores, for the CPU parts of a
// scene's start-up (glTF mesh geometries).
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace vkrt {

/// Calls work(i) once for every i in [0, count), in no set order, on up to
/// hardware_concurrency() threads (the caller's among them). Where items
/// throw, every item still runs and then the exception of the lowest such i
/// is rethrown: the same error for any number of threads.
template <class Work>
void forEachInParallel(size_t count, const Work& work)
{
    std::vector<std::exception_ptr> errors(count);
    std::atomic<size_t> next{0};
    const auto worker = [&] {
        for (size_t i; (i = next++) < count;) {
            try {
                work(i);
            } catch (...) {
                errors[i] = std::current_exception();
            }
        }
    };
    const size_t threads = std::min<size_t>(count, std::max(1u, std::thread::hardware_concurrency()));
    {
        std::vector<std::jthread> pool;
        for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
        worker();
    } // joins the pool
    for (const std::exception_ptr& error : errors)
        if (error) std::rethrow_exception(error);
}

} // namespace vkrt
