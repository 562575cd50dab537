#include "workflow/study/crash_records.h"

#include <csignal>

namespace mmm::workflow {

void record_crash(Database& database, const CrashRecord& crash) {
  database.prepare("INSERT INTO crashes(node, cache_key, signal, noticed_at) VALUES (?, ?, ?, ?)")
      .bind_text(1, crash.node)
      .bind_text(2, crash.cache_key)
      .bind_int64(3, crash.signal)
      .bind_text(4, crash.noticed_at)
      .step();
  database
      .prepare(
          "UPDATE executions SET status = 'failed', error = ? WHERE status = 'running' AND "
          "node = ? AND cache_key = ?")
      .bind_text(1, crash_error(crash))
      .bind_text(2, crash.node)
      .bind_text(3, crash.cache_key)
      .step();
}

std::optional<CrashRecord> find_crash(Database& database, const std::string& node,
                                      const std::string& cache_key) {
  Statement select = database.prepare(
      "SELECT signal, noticed_at FROM crashes WHERE cache_key = ? AND node = ? ORDER BY id DESC "
      "LIMIT 1");
  select.bind_text(1, cache_key).bind_text(2, node);
  if (!select.step()) return std::nullopt;
  return CrashRecord{node, cache_key, static_cast<int>(select.column_int64(0)),
                     select.column_text(1)};
}

std::string signal_description(int signal) {
  switch (signal) {
    case SIGSEGV:
      return "SIGSEGV (invalid memory access or stack overflow)";
    case SIGBUS:
      return "SIGBUS (bus error)";
    case SIGFPE:
      return "SIGFPE (arithmetic fault)";
    case SIGILL:
      return "SIGILL (illegal instruction)";
    case SIGABRT:
      return "SIGABRT (abort: an internal check failed)";
    default:
      return "signal " + std::to_string(signal);
  }
}

std::string crash_error(const CrashRecord& crash) {
  return "node '" + crash.node + "' crashed mmm with these inputs and parameters (" +
         signal_description(crash.signal) + "; noticed " + crash.noticed_at +
         "); it is not run again with them, so that one bad input cannot crash every run. "
         "hint: check the files it reads (a broken or hostile file is the usual cause) and "
         "change the input or a parameter, or run with --retry-crashed to try it again";
}

}  // namespace mmm::workflow
