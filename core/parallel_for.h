#pragma once
// job(i) for every i in [0, count) on `threads` threads (the caller's among
// them; machine_threads() for all the machine has), items handed out one at a time so uneven jobs
// balance. The first exception stops the handing out and is rethrown once every thread is done.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace mmm {

// The machine's hardware threads, at least 1.
inline int machine_threads() {
  return static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
}

template <typename Job>
void parallel_for(std::size_t count, int threads, const Job& job) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto work = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        const std::scoped_lock lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  std::vector<std::jthread> pool;
  const int extra = std::min<int>(std::max(1, threads), static_cast<int>(count)) - 1;
  pool.reserve(static_cast<std::size_t>(std::max(0, extra)));
  for (int t = 0; t < extra; ++t) pool.emplace_back(work);
  work();
  pool.clear();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace mmm
