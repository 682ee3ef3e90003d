#pragma once

#include <cstddef>
#include <functional>

namespace ecv {

/// Runs `work` on `threads` threads at once, this one included, and waits for all of them. Each call of `work` takes
/// its share of a common job (e.g. from an atomic counter) and keeps its own buffers. The first exception thrown by
/// any of them is rethrown here, after all have finished.
void RunOnThreads(int threads, const std::function<void()>& work);

/// Calls work(i) for every i in [0, count) on at most `threads` threads (RunOnThreads), each i once, in no set order.
/// After an exception no further i is started.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& work);

}  // namespace ecv
