#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "core/error.h"

namespace ecv {

void CheckThreadCount(const std::string& source, int threads) {
  if (threads < 1 || threads > kMaxThreads) {
    ThrowInputError(source, "threads", "1 to " + std::to_string(kMaxThreads), std::to_string(threads));
  }
}

void RunOnThreads(int threads, const std::function<void()>& work) {
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto guarded = [&] {
    try {
      work();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  workers.reserve(static_cast<size_t>(std::max(threads - 1, 0)));  // before any thread runs: no joinable one is lost
  for (int t = 1; t < threads; ++t) {
    try {
      workers.emplace_back(guarded);
    } catch (const std::system_error&) {
      break;  // out of threads: the work is shared out among those that run
    }
  }
  guarded();
  for (std::thread& worker : workers) worker.join();
  if (failure) std::rethrow_exception(failure);
}

void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& work) {
  std::atomic<size_t> next{0};
  auto run = [&] {
    for (size_t i = next++; i < count; i = next++) {
      try {
        work(i);
      } catch (...) {
        next = count;  // no further i is started
        throw;
      }
    }
  };
  RunOnThreads(static_cast<int>(std::min(count, static_cast<size_t>(std::max(threads, 1)))), run);
}

}  // namespace ecv
