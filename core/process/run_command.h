#pragma once
// Runs a program (no shell: the arguments go as they are, so nothing in them
// is interpreted) and collects what it writes, for the tools mmm drives
// (Slurm's sbatch, squeue, scontrol, scancel).

#include <cstddef>
#include <string>
#include <vector>

namespace mmm::process {

struct CommandResult {
  int exit_code = 0;   // the program's exit status; 128 + N when signal N ended it
  std::string output;  // its standard output and error, interleaved
};

// Runs argv[0] (searched on PATH) with the arguments argv[1..]; returns when
// it has ended. At most `max_output` bytes of output are kept (the rest is
// read and dropped). Throws IoError naming the program when it cannot be
// started (not installed, not executable), with a hint.
CommandResult run_command(const std::vector<std::string>& argv,
                          std::size_t max_output = std::size_t{1} << 20U);

}  // namespace mmm::process
