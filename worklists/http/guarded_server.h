#pragma once
// An HTTP server (cpp-httplib) whose connections cannot hold it hostage.
//
// cpp-httplib gives each connection to one thread of a fixed pool and waits
// up to its read timeout for every byte: a client that trickles a header line
// every few seconds keeps a thread forever, and eight such clients stopped the
// station from answering anyone. Here every connection serves one request and
// must deliver all of it (request line, headers, body) within
// `request_deadline`, reading at most `max_header_bytes + max_body_bytes`
// whatever the framing says, and must take the response within
// `response_deadline`; then the socket is closed. Chunked request bodies are
// refused by the caller's pre-routing handler (they carry no length to check
// before reading), and the worker pool is larger than cpp-httplib's default.

#include <httplib.h>

// httplib.h includes <resolv.h>, whose macro `_res` renames parameters of
// Eigen's headers included after it (in the same unity batch, say).
#ifdef _res
#undef _res
#endif

#include <filesystem>
#include <memory>

#include "worklists/http/connection_limits.h"

namespace mmm::worklists::http {

class GuardedServer : public httplib::Server {
 public:
  explicit GuardedServer(ConnectionLimits limits);
  ~GuardedServer() override;
  GuardedServer(const GuardedServer&) = delete;
  GuardedServer& operator=(const GuardedServer&) = delete;
  GuardedServer(GuardedServer&&) = delete;
  GuardedServer& operator=(GuardedServer&&) = delete;

  // Serves HTTPS (TLS 1.2 or newer, OpenSSL) with this certificate chain and
  // private key, both PEM. Throws IoError naming the file that cannot be read
  // or does not fit (a key that is not the certificate's). The handshake
  // counts against the request deadline.
  void use_tls(const std::filesystem::path& certificate, const std::filesystem::path& key);

  [[nodiscard]] const ConnectionLimits& limits() const { return limits_; }

 private:
  // Called by cpp-httplib's listening loop on a pool thread for each
  // accepted socket.
  bool process_and_close_socket(socket_t sock) override;

  struct Tls;
  ConnectionLimits limits_;
  std::unique_ptr<Tls> tls_;
};

}  // namespace mmm::worklists::http
