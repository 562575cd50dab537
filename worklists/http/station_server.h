#pragma once
// The operator web UI of the manual tasks (`mmm serve`): an HTTP server
// over the studies of a root folder. It serves the page (static files handed
// in by the caller, e.g. embedded in the binary) and the JSON API the page
// uses, documented in docs/operators.md ("Operator web UI and its JSON API"):
//
//   GET  /api/whoami                       the operator of the token
//   GET  /api/worklist?state=&assignee=&all=1
//   GET  /api/tasks/{id}                   the task with its request (views, P matrices)
//   GET  /api/tasks/{id}/views/{view}/pixels   16-bit samples, little-endian, row-major
//   POST /api/tasks/{id}/claim | release
//   POST /api/tasks/{id}/preview           what a submission would give (reprojection errors)
//   POST /api/tasks/{id}/submit            submit; accepted -> the study resumes at once
//                                          (body: the submission's fields, those its node
//                                          type's task behaviour names, plus "reason")
//   GET  /api/studies/{study}/status       node states (plan_study), tasks, the runner
//
// Every /api/ request carries an operator token (`mmm operator add NAME`) as
// "Authorization: Bearer TOKEN"; without a valid one the answer is 401, given
// before any request body is read. Each connection serves one request within
// the deadlines and sizes of options.limits (connection_limits.h); a chunked
// request body is refused (411: send Content-Length). No CORS headers are
// sent: browsers keep pages of other origins from reading the API. The
// audit trail names the operator the token belongs to. Errors are JSON:
// {"error": "...", "hint": "..."} with 400 (bad request), 401, 404 (no such
// task, study or view), 409 (the task's state forbids it: TaskError), 500.

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "workflow/node_registry.h"
#include "workflow/run/run_study.h"
#include "worklists/http/connection_limits.h"

namespace mmm::worklists::http {

// A file the server returns as is, by URL path ("/", "/station.js", ...).
struct StaticFile {
  std::string content_type;
  std::string bytes;
};

struct ServerOptions {
  std::filesystem::path root;  // the studies' folder (the worklist's root)
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port (see StationServer::port)
  // Per connection: deadlines, sizes, connections served at once.
  ConnectionLimits limits;
  // Both set: HTTPS with this PEM certificate chain and private key.
  std::filesystem::path tls_certificate;
  std::filesystem::path tls_key;
  // How resumed studies run (jobs, provenance recorded with each run).
  workflow::RunOptions run;
  std::string mmm_version;  // recorded in the audit trail with each action
  // Period of the sweep that resumes studies whose accepted work waits for
  // their downstream nodes (resumer: study_resumer.h); 0: none.
  std::chrono::milliseconds sweep_interval{10000};
  std::map<std::string, StaticFile> files;  // "/" is the page
  // One line per request that failed and per background run; nullptr: none.
  std::function<void(const std::string&)> log;
};

class StationServer {
 public:
  // Checks the root and binds the address (throws IoError naming host:port
  // when it cannot, e.g. the port is taken). `registry` must outlive the
  // server.
  StationServer(ServerOptions options, const workflow::NodeRegistry& registry);
  ~StationServer();
  StationServer(const StationServer&) = delete;
  StationServer& operator=(const StationServer&) = delete;
  StationServer(StationServer&&) = delete;
  StationServer& operator=(StationServer&&) = delete;

  // The port bound (the chosen one when options.port was 0).
  [[nodiscard]] int port() const;
  // Serves until stop() (from another thread or a signal handler's thread).
  void run();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mmm::worklists::http
