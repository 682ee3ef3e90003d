#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace ecv {

/// The most worker threads of any stage: a bound on every `threads` option and --threads flag.
constexpr int kMaxThreads = 256;

/// Throws InputError "<source>: threads: expected 1 to 256, got N" for a count outside [1, kMaxThreads].
void CheckThreadCount(const std::string& source, int threads);

/// Runs `work` on `threads` threads at once, this one included, and waits for all of them. Each call of `work` takes
/// its share of a common job (e.g. from an atomic counter) and keeps its own buffers. The first exception thrown by
/// any of them is rethrown here, after all have finished. Where the system starts fewer threads, those started do the
/// job.
void RunOnThreads(int threads, const std::function<void()>& work);

/// Calls work(i) for every i in [0, count) on at most `threads` threads (RunOnThreads), each i once, in no set order.
/// After an exception no further i is started.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& work);

}  // namespace ecv
