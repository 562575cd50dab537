#include "worklists/http/station_server.h"

#include <cstdint>
#include <exception>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/image/radiograph_pair.h"
#include "workflow/run/study_plan.h"
#include "workflow/study/study.h"
#include "worklists/http/study_resumer.h"
#include "worklists/operators.h"
#include "worklists/task_actions.h"
#include "worklists/worklist.h"

// Last: httplib.h includes <resolv.h>, whose macro `_res` would rename
// parameters of Eigen's headers (included above through core/).
#include "worklists/http/guarded_server.h"

namespace mmm::worklists::http {
namespace {

using Json = nlohmann::json;

constexpr const char* kJson = "application/json";
constexpr const char* kTokenHint =
    "send the operator token as 'Authorization: Bearer TOKEN'; an operator gets one from "
    "'mmm operator add NAME --root ROOT' (shown once; --replace makes a new one)";

// What the client asked for does not exist: 404.
class NotFoundError : public InvalidInputError {
 public:
  using InvalidInputError::InvalidInputError;
};

// The request itself is malformed: 400.
class BadRequestError : public InvalidInputError {
 public:
  using InvalidInputError::InvalidInputError;
};

void send_json(httplib::Response& response, int status, const Json& body) {
  response.status = status;
  response.set_header("Cache-Control", "no-store");
  response.set_content(body.dump(), kJson);
}

void send_error(httplib::Response& response, int status, const std::string& error,
                const std::string& hint) {
  send_json(response, status, {{"error", error}, {"hint", hint}});
}

// "Bearer TOKEN" -> TOKEN; empty when the header is missing or of another
// scheme.
std::string bearer_token(const httplib::Request& request) {
  const std::string header = request.get_header_value("Authorization");
  constexpr std::string_view kScheme = "Bearer ";
  if (header.size() <= kScheme.size() || header.compare(0, kScheme.size(), kScheme) != 0) {
    return {};
  }
  std::string token = header.substr(kScheme.size());
  while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) token.pop_back();
  return token;
}

Json parse_body(const httplib::Request& request) {
  if (request.body.empty()) return Json::object();
  Json body = parse_json_or_discarded(request.body);
  if (body.is_discarded() || !body.is_object()) {
    throw BadRequestError("the request body is not a JSON object");
  }
  return body;
}

// The worklist view of a task: the task without its (large) request and
// values, with its study and age.
Json entry_summary(const WorklistEntry& entry) {
  Json json = task_to_json(entry.task);
  json.erase("request");
  json.erase("submission");
  json.erase("result");
  json["study"] = entry.study;
  json["patient"] = entry.patient;
  json["age_seconds"] = entry.age_seconds;
  json["age"] = format_age(entry.age_seconds);
  return json;
}

Json entry_detail(const WorklistEntry& entry) {
  Json json = task_to_json(entry.task);
  json["study"] = entry.study;
  json["patient"] = entry.patient;
  json["age_seconds"] = entry.age_seconds;
  json["age"] = format_age(entry.age_seconds);
  return json;
}

Json outcome_json(const SubmitOutcome& outcome) {
  return {{"task", task_to_json(outcome.task)}, {"accepted", outcome.accepted},
          {"correction", outcome.correction},   {"awaiting_review", outcome.awaiting_review},
          {"reasons", outcome.reasons},         {"values", outcome.values}};
}

// 16-bit samples as little-endian bytes, row-major.
std::string little_endian_samples(const image::GrayImage16& image) {
  std::string bytes(image.pixels.size() * 2, '\0');
  for (std::size_t k = 0; k < image.pixels.size(); ++k) {
    const std::uint16_t sample = image.pixels[k];
    bytes[2 * k] = static_cast<char>(sample & 0xFFU);
    bytes[(2 * k) + 1] = static_cast<char>(sample >> 8U);
  }
  return bytes;
}

}  // namespace

// Named, not file-local, because StationServer::Impl holds it.
namespace station_detail {

// Decoded views of the radiograph pairs already shown, by "<pair hash>/<view>"
// (a few megabytes each: the oldest go when more than kCapacity are kept).
class PixelCache {
 public:
  struct Pixels {
    int width = 0;
    int height = 0;
    std::string bytes;
  };

  std::shared_ptr<const Pixels> get(const workflow::Study& study, const std::string& pair_hash,
                                    const std::string& view) {
    const std::string key = pair_hash + "/" + view;
    {
      const std::scoped_lock lock(mutex_);
      for (const auto& [cached_key, pixels] : entries_) {
        if (cached_key == key) return pixels;
      }
    }
    const image::RadiographPair pair = image::radiograph_pair_from_json_text(
        study.artifacts().get(pair_hash), study.dir() / "artifacts" / pair_hash);
    const image::GrayImage16 decoded = pair.image(view);
    auto pixels = std::make_shared<Pixels>();
    pixels->width = decoded.width;
    pixels->height = decoded.height;
    pixels->bytes = little_endian_samples(decoded);
    const std::scoped_lock lock(mutex_);
    entries_.emplace_back(key, pixels);
    if (entries_.size() > kCapacity) entries_.erase(entries_.begin());
    return pixels;
  }

 private:
  static constexpr std::size_t kCapacity = 8;
  std::mutex mutex_;
  std::vector<std::pair<std::string, std::shared_ptr<const Pixels>>> entries_;
};

}  // namespace station_detail

struct StationServer::Impl {
  ServerOptions options;
  const workflow::NodeRegistry& registry;
  GuardedServer server;
  int port = 0;
  station_detail::PixelCache pixels;
  std::mutex log_mutex;
  std::unique_ptr<StudyResumer> resumer;

  Impl(ServerOptions server_options, const workflow::NodeRegistry& node_registry)
      : options(std::move(server_options)), registry(node_registry), server(options.limits) {}

  void log(const std::string& line) {
    if (!options.log) return;
    const std::scoped_lock lock(log_mutex);
    options.log(line);
  }

  // The task `id` under the root; NotFoundError when there is none.
  [[nodiscard]] WorklistEntry locate(const std::string& id) const {
    try {
      return locate_task(options.root, id);
    } catch (const TaskError&) {
      throw;
    } catch (const InvalidInputError& error) {
      throw NotFoundError(error.what());
    }
  }

  [[nodiscard]] Actor actor(const std::string& operator_name) const {
    return {operator_name, options.mmm_version, is_supervisor(options.root, operator_name)};
  }

  // The study folder called `study` (its path relative to the root, as the
  // worklist gives it); NotFoundError when no study has that name.
  [[nodiscard]] std::filesystem::path study_dir(const std::string& study) const {
    for (const std::filesystem::path& dir : find_studies(options.root)) {
      if (std::filesystem::relative(dir, options.root).generic_string() == study) return dir;
    }
    throw NotFoundError("no study '" + study + "' under " + options.root.string());
  }

  // The operator of the request's token; nullopt (and the 401 or 500
  // response written) when there is none.
  std::optional<std::string> authenticate(const httplib::Request& request,
                                          httplib::Response& response) {
    const std::string token = bearer_token(request);
    std::optional<std::string> name;
    try {
      if (!token.empty()) name = operator_for_token(options.root, token);
    } catch (const std::exception& error) {
      log(request.method + " " + request.path + ": " + error.what());
      send_error(response, 500, error.what(), "check the operators file of the root");
      return std::nullopt;
    }
    if (!name) {
      response.set_header("WWW-Authenticate", "Bearer");
      send_error(response, 401,
                 token.empty() ? "no operator token in the request" : "unknown operator token",
                 kTokenHint);
    }
    return name;
  }

  // Runs after the headers and before the body is read: a chunked body
  // (no length to check first) is refused, and an API request without a
  // valid token is answered 401 without reading its body.
  httplib::Server::HandlerResponse before_body(const httplib::Request& request,
                                               httplib::Response& response) {
    if (request.has_header("Transfer-Encoding")) {
      send_error(response, 411, "chunked request bodies are not accepted",
                 "send the body with a Content-Length (at most " +
                     std::to_string(options.limits.max_body_bytes >> 10U) + " KiB)");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (request.path.rfind("/api/", 0) == 0 && !authenticate(request, response)) {
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  }

  using ApiHandler =
      std::function<void(const httplib::Request&, httplib::Response&, const std::string&)>;

  // Authenticates the request, runs `handler` with the operator's name and
  // turns exceptions into JSON errors.
  httplib::Server::Handler api(ApiHandler handler) {
    return [this, handler = std::move(handler)](const httplib::Request& request,
                                                httplib::Response& response) {
      const std::optional<std::string> name = authenticate(request, response);
      if (!name) return;
      try {
        handler(request, response, *name);
      } catch (const NotFoundError& error) {
        send_error(response, 404, error.what(), "GET /api/worklist lists the open tasks");
      } catch (const BadRequestError& error) {
        send_error(response, 400, error.what(),
                   "see docs/operators.md: Operator web UI and its JSON API");
      } catch (const TaskError& error) {
        send_error(response, 409, error.what(), "reload the task: its state may have changed");
      } catch (const InvalidInputError& error) {
        send_error(response, 400, error.what(),
                   "see docs/operators.md: Operator web UI and its JSON API");
      } catch (const Json::exception& error) {
        send_error(response, 400, error.what(), "the body must be JSON as in docs/operators.md");
      } catch (const std::exception& error) {
        log(request.method + " " + request.path + ": " + error.what());
        send_error(response, 500, error.what(), "the server's log says more");
      }
    };
  }

  void whoami(httplib::Response& response, const std::string& name) const {
    send_json(response, 200,
              {{"operator", name},
               {"root", options.root.string()},
               {"mmm_version", options.mmm_version}});
  }

  void worklist(const httplib::Request& request, httplib::Response& response) const {
    WorklistFilter filter;
    if (request.has_param("state") && !request.get_param_value("state").empty()) {
      const std::string state = request.get_param_value("state");
      filter.state = task_state_from_name(state);
      if (!filter.state) {
        throw BadRequestError("unknown task state '" + state + "'; states: " + task_state_names());
      }
      filter.include_closed = true;
    }
    if (request.has_param("assignee") && !request.get_param_value("assignee").empty()) {
      filter.assignee = request.get_param_value("assignee");
    }
    if (request.get_param_value("all") == "1") filter.include_closed = true;
    Json tasks = Json::array();
    for (const WorklistEntry& entry : list_worklist(options.root, filter)) {
      tasks.push_back(entry_summary(entry));
    }
    send_json(response, 200, {{"tasks", tasks}});
  }

  void task(const std::string& id, httplib::Response& response) const {
    send_json(response, 200, {{"task", entry_detail(locate(id))}});
  }

  void view_pixels(const std::string& id, const std::string& view, httplib::Response& response) {
    const WorklistEntry entry = locate(id);
    const Json& request = entry.task.request;
    bool known = false;
    if (request.contains("views") && request["views"].is_array()) {
      for (const Json& candidate : request["views"]) {
        known = known || candidate.value("name", std::string()) == view;
      }
    }
    if (!known || !request.contains("radiographs") || !request["radiographs"].is_string()) {
      throw NotFoundError("task " + entry.task.id + " has no view '" + view + "' with an image");
    }
    const workflow::Study study = workflow::Study::open(entry.study_dir, registry);
    const std::shared_ptr<const station_detail::PixelCache::Pixels> samples =
        pixels.get(study, request["radiographs"].get<std::string>(), view);
    response.set_header("X-Image-Width", std::to_string(samples->width));
    response.set_header("X-Image-Height", std::to_string(samples->height));
    response.set_header("Cache-Control", "private, max-age=3600");
    response.set_content(samples->bytes, "application/octet-stream");
  }

  void claim_or_release(const std::string& id, bool claim, const std::string& name,
                        httplib::Response& response) const {
    const WorklistEntry entry = locate(id);
    workflow::Study study = workflow::Study::open(entry.study_dir, registry);
    const Task task = claim ? claim_task(study, entry.task.id, actor(name))
                            : release_task(study, entry.task.id, actor(name));
    send_json(response, 200, {{"task", task_to_json(task)}});
  }

  // The submission in a request body: the fields the task's node type
  // takes (its task behaviour's submission fields), without the body's own
  // ("reason").
  static Json submission_of(const workflow::Study& study, const Task& task, const Json& body) {
    const std::vector<std::string>& fields = task_behaviour(study, task).submission_fields;
    Json submission = Json::object();
    std::string names;
    for (const std::string& field : fields) {
      if (body.contains(field)) submission[field] = body[field];
      names += (names.empty() ? "\"" : ", \"") + field + "\"";
    }
    if (submission.empty()) {
      throw BadRequestError("the body has none of the fields of a submission for task " + task.id +
                            ": " + names);
    }
    return submission;
  }

  void preview(const std::string& id, const httplib::Request& request,
               httplib::Response& response) const {
    const WorklistEntry entry = locate(id);
    workflow::Study study = workflow::Study::open(entry.study_dir, registry);
    const SubmitOutcome outcome = preview_submission(
        study, entry.task.id, submission_of(study, entry.task, parse_body(request)));
    send_json(response, 200, {{"reasons", outcome.reasons}, {"values", outcome.values}});
  }

  void submit(const std::string& id, const httplib::Request& request, httplib::Response& response,
              const std::string& name) const {
    const WorklistEntry entry = locate(id);
    const Json body = parse_body(request);
    workflow::Study study = workflow::Study::open(entry.study_dir, registry);
    const SubmitOutcome outcome =
        submit_task(study, entry.task.id, actor(name), submission_of(study, entry.task, body),
                    body.value("reason", ""));
    Json json = outcome_json(outcome);
    json["study"] = entry.study;
    json["resuming"] = outcome.accepted;
    if (outcome.accepted) resumer->request(entry.study_dir);
    send_json(response, 200, json);
  }

  void study_status(const std::string& study_name, httplib::Response& response) const {
    const std::filesystem::path dir = study_dir(study_name);
    workflow::Study study = workflow::Study::open(dir, registry);
    const workflow::StudyPlan plan = workflow::plan_study(study, false);
    Json nodes = Json::array();
    Json counts = Json::object();
    for (const workflow::NodePlan& node : plan.nodes) {
      const std::string state(workflow::node_state_name(node.state));
      nodes.push_back({{"name", node.node->id},
                       {"type", node.node->type},
                       {"state", state},
                       {"reason", node.reason}});
      counts[state] = counts.value(state, 0) + 1;
    }
    const RunnerStatus runner = resumer->status(dir);
    std::string state = "pending";
    if (runner.state != RunnerState::kIdle) {
      state = "running";
    } else if (plan.count(workflow::NodeState::kFailed) +
                   plan.count(workflow::NodeState::kInvalid) >
               0) {
      state = "failed";
    } else if (plan.count(workflow::NodeState::kCached) == static_cast<int>(plan.nodes.size())) {
      state = "done";
    } else if (plan.count(workflow::NodeState::kWaiting) > 0) {
      state = "waiting";
    }
    WorklistFilter filter;
    filter.include_closed = true;
    Json tasks = Json::array();
    for (const WorklistEntry& entry : list_worklist(options.root, filter)) {
      if (entry.study_dir == dir) tasks.push_back(entry_summary(entry));
    }
    send_json(
        response, 200,
        {{"study", study_name},
         {"state", state},
         {"nodes", nodes},
         {"counts", counts},
         {"runner", {{"state", runner_state_name(runner.state)}, {"last_run", runner.last_run}}},
         {"tasks", tasks}});
  }

  void routes() {
    server.set_pre_routing_handler(
        [this](const httplib::Request& request, httplib::Response& response) {
          return before_body(request, response);
        });
    server.Get("/api/whoami", api([this](const httplib::Request&, httplib::Response& response,
                                         const std::string& name) { whoami(response, name); }));
    server.Get("/api/worklist",
               api([this](const httplib::Request& request, httplib::Response& response,
                          const std::string&) { worklist(request, response); }));
    server.Get(R"(/api/tasks/([0-9a-f]+))",
               api([this](const httplib::Request& request, httplib::Response& response,
                          const std::string&) { task(request.matches[1], response); }));
    server.Get(R"(/api/tasks/([0-9a-f]+)/views/([A-Za-z0-9_.-]+)/pixels)",
               api([this](const httplib::Request& request, httplib::Response& response,
                          const std::string&) {
                 view_pixels(request.matches[1], request.matches[2], response);
               }));
    server.Post(R"(/api/tasks/([0-9a-f]+)/(claim|release))",
                api([this](const httplib::Request& request, httplib::Response& response,
                           const std::string& name) {
                  claim_or_release(request.matches[1], request.matches[2] == "claim", name,
                                   response);
                }));
    server.Post(
        R"(/api/tasks/([0-9a-f]+)/preview)",
        api([this](const httplib::Request& request, httplib::Response& response,
                   const std::string&) { preview(request.matches[1], request, response); }));
    server.Post(R"(/api/tasks/([0-9a-f]+)/submit)",
                api([this](const httplib::Request& request, httplib::Response& response,
                           const std::string& name) {
                  submit(request.matches[1], request, response, name);
                }));
    server.Get(R"(/api/studies/(.+)/status)",
               api([this](const httplib::Request& request, httplib::Response& response,
                          const std::string&) { study_status(request.matches[1], response); }));
    const auto unknown =
        api([](const httplib::Request& request, httplib::Response& response, const std::string&) {
          send_error(response, 404, "no API endpoint " + request.method + " " + request.path,
                     "see docs/operators.md: Operator web UI and its JSON API");
        });
    server.Get("/api/.*", unknown);
    server.Post("/api/.*", unknown);
    server.Get("/(.*)", [this](const httplib::Request& request, httplib::Response& response) {
      const std::string path = request.path == "/" ? "/index.html" : request.path;
      const auto found = options.files.find(path);
      if (found == options.files.end()) {
        response.status = 404;
        response.set_content("not found: " + request.path + "\n", "text/plain");
        return;
      }
      response.set_header("Cache-Control", "no-cache");
      response.set_content(found->second.bytes, found->second.content_type);
    });
  }
};

StationServer::StationServer(ServerOptions options, const workflow::NodeRegistry& registry)
    : impl_(std::make_unique<Impl>(std::move(options), registry)) {
  Impl& impl = *impl_;
  if (!std::filesystem::is_directory(impl.options.root)) {
    throw IoError(impl.options.root,
                  "is not a folder; hint: give the folder that holds the studies (--root)");
  }
  ResumerOptions resumer;
  resumer.run = impl.options.run;
  resumer.sweep_interval = impl.options.sweep_interval;
  impl.resumer = std::make_unique<StudyResumer>(
      impl.options.root, registry, resumer, [this](const std::string& line) { impl_->log(line); });
  impl.routes();
  if (!impl.options.tls_certificate.empty() || !impl.options.tls_key.empty()) {
    if (impl.options.tls_certificate.empty() || impl.options.tls_key.empty()) {
      throw InvalidInputError(
          "HTTPS needs both a certificate and its private key (--tls-cert and --tls-key)");
    }
    impl.server.use_tls(impl.options.tls_certificate, impl.options.tls_key);
  }
  // cpp-httplib's default socket options add SO_REUSEPORT, with which a
  // second server binds the port of a running one without an error (and the
  // kernel splits the connections between them). Only SO_REUSEADDR: a
  // restart right after a stop still binds, a taken port is an error.
  impl.server.set_socket_options([](::socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  const std::string address = impl.options.host + ":" + std::to_string(impl.options.port);
  if (impl.options.port == 0) {
    impl.port = impl.server.bind_to_any_port(impl.options.host);
  } else if (impl.server.bind_to_port(impl.options.host, impl.options.port)) {
    impl.port = impl.options.port;
  }
  if (impl.port <= 0) {
    throw IoError(address,
                  "cannot listen there; hint: another program may use the port (--port), or the "
                  "host is not an address of this machine (--host)");
  }
}

StationServer::~StationServer() {
  impl_->server.stop();
  impl_->resumer.reset();  // waits for the studies being run
}

int StationServer::port() const { return impl_->port; }

void StationServer::run() { impl_->server.listen_after_bind(); }

void StationServer::stop() { impl_->server.stop(); }

}  // namespace mmm::worklists::http
