// mmm serve: the operator web UI of the landmark station (worklists/http/).

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <iostream>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "app/commands/commands.h"
#include "core/errors.h"
#include "mmm_git_revision.h"
#include "station_files.h"  // generated from web/station/ (app/CMakeLists.txt)
#include "worklists/http/station_server.h"

namespace mmm::app {
namespace {

struct ServeArgs {
  std::string root;
  std::string host = "127.0.0.1";
  int port = 8080;
  int jobs = 1;
  double sweep_seconds = 10;
  std::string tls_certificate;
  std::string tls_key;
};

// Whether `host` is an address of this machine only (loopback).
bool is_loopback(const std::string& host) {
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// Served beyond this machine: say loudly what that means.
void warn_about_exposure(const ServeArgs& args) {
  if (is_loopback(args.host)) return;
  const bool tls = !args.tls_certificate.empty();
  std::cerr << "mmm serve: WARNING: listening on " << args.host
            << ", reachable from other machines. Operator tokens and patient images cross the "
               "network "
            << (tls ? "encrypted (HTTPS); check that the certificate is one the operators' "
                      "browsers trust."
                    : "IN CLEAR TEXT: anyone on the network path can read them and act as an "
                      "operator. Give --tls-cert and --tls-key, or keep the default host "
                      "127.0.0.1 behind an HTTPS reverse proxy.")
            << std::endl;
}

std::string content_type(std::string_view name) {
  const auto ends_with = [name](std::string_view suffix) { return name.ends_with(suffix); };
  if (ends_with(".html")) return "text/html; charset=utf-8";
  if (ends_with(".js")) return "text/javascript; charset=utf-8";
  if (ends_with(".css")) return "text/css; charset=utf-8";
  if (ends_with(".png")) return "image/png";
  if (ends_with(".svg")) return "image/svg+xml";
  return "application/octet-stream";
}

// The embedded page, by URL path ("/index.html", "/station.js", ...).
std::map<std::string, worklists::http::StaticFile> station_files() {
  std::map<std::string, worklists::http::StaticFile> files;
  for (const embedded::EmbeddedFile& file : embedded::kStationFiles) {
    files["/" + std::string(file.name)] = {content_type(file.name),
                                           std::string(file.bytes, file.bytes + file.size)};
  }
  return files;
}

void run_serve(const ServeArgs& args, const workflow::NodeRegistry& registry) {
  // SIGINT and SIGTERM are taken by one thread (sigwait), which stops the
  // server; every other thread, started below, inherits the blocked mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  worklists::http::ServerOptions options;
  options.root = args.root;
  options.host = args.host;
  options.port = args.port;
  options.tls_certificate = args.tls_certificate;
  options.tls_key = args.tls_key;
  options.run.jobs = args.jobs;
  options.run.provenance = {MMM_VERSION, MMM_GIT_REVISION};
  options.mmm_version = MMM_VERSION;
  options.sweep_interval =
      std::chrono::milliseconds(static_cast<std::int64_t>(args.sweep_seconds * 1000));
  options.files = station_files();
  options.log = [](const std::string& line) { std::cerr << "mmm serve: " << line << std::endl; };
  worklists::http::StationServer server(std::move(options), registry);
  warn_about_exposure(args);

  std::thread stopper([&server, &signals] {
    int signal = 0;
    sigwait(&signals, &signal);
    server.stop();
  });
  std::cout << "mmm serve: the landmark station of " << args.root << " at "
            << (args.tls_certificate.empty() ? "http" : "https") << "://" << args.host << ':'
            << server.port() << "/\n"
            << "operators sign in with their token ('mmm operator add NAME --root " << args.root
            << "'); Ctrl-C stops" << std::endl;
  server.run();
  // When the server stopped by itself, wake the signal thread so it ends.
  kill(getpid(), SIGTERM);
  stopper.join();
  std::cout << "mmm serve: stopped" << std::endl;
}

}  // namespace

void register_serve_commands(CLI::App& app, const workflow::NodeRegistry& registry) {
  auto args = std::make_shared<ServeArgs>();
  auto* serve = app.add_subcommand(
      "serve", "Serve the operator web UI (landmark station) of the studies under a root folder");
  serve->add_option("--root", args->root, "Folder holding the studies (the worklist's root)")
      ->required()
      ->check(CLI::ExistingDirectory);
  serve->add_option("--port,-p", args->port, "TCP port (0: any free port, printed)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  serve
      ->add_option("--host", args->host,
                   "Address to listen on (default: this machine only; another address makes "
                   "the page reachable from the network: use --tls-cert and --tls-key)")
      ->capture_default_str();
  serve->add_option("--jobs,-j", args->jobs, "Nodes run at the same time when a study resumes")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  serve
      ->add_option("--sweep", args->sweep_seconds,
                   "Every SECONDS, resume studies whose accepted work waits (0: never)")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  serve->add_option("--tls-cert", args->tls_certificate, "HTTPS: the server's certificate (PEM)")
      ->check(CLI::ExistingFile);
  serve->add_option("--tls-key", args->tls_key, "HTTPS: the certificate's private key (PEM)")
      ->check(CLI::ExistingFile);
  serve->callback([args, &registry] { run_serve(*args, registry); });
}

}  // namespace mmm::app
