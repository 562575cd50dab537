#pragma once
// The main() of the suites that also measure accuracy: the accuracy table
// first (unless MMM_BENCH_SKIP_ACCURACY is set), then the Google Benchmarks;
// any error ends the suite with its message and exit code 1.

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <exception>
#include <iostream>

namespace mmm::bench {

inline int run_suite(int argc, char** argv, const char* program, void (*write_accuracy_table)()) {
  try {
    benchmark::Initialize(&argc, argv);
    if (std::getenv("MMM_BENCH_SKIP_ACCURACY") == nullptr) write_accuracy_table();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
  } catch (const std::exception& error) {
    std::cerr << program << ": " << error.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace mmm::bench
