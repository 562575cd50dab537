#pragma once
// Runs a program (no shell: the arguments go as they are, so nothing in them
// is interpreted) and collects what it writes, for the tools mmm drives
// (Slurm's srun, squeue, scontrol).

#include <cstddef>
#include <string>
#include <vector>

namespace mmm::process {

struct CommandResult {
  int exit_code = 0;   // the program's exit status; 128 + N when signal N ended it
  std::string output;  // its standard output and error, interleaved
};

struct CommandOptions {
  // At most this many bytes of output are kept: the first half and the last
  // half of it when there is more (the rest is read and dropped).
  std::size_t max_output = std::size_t{1} << 20U;
  // The signal the program gets if the calling thread ends first (Linux
  // PR_SET_PDEATHSIG), e.g. SIGTERM, on which srun cancels its Slurm job: a
  // killed coordinator leaves no job behind. 0: none.
  int parent_death_signal = 0;
};

// Runs argv[0] (searched on PATH) with the arguments argv[1..]; returns when
// it has ended. Its standard input is /dev/null. Throws IoError naming the
// program when it cannot be started (not installed, not executable), with a
// hint.
CommandResult run_command(const std::vector<std::string>& argv, const CommandOptions& options = {});

}  // namespace mmm::process
