#include "worklists/http/guarded_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <string>

#include "core/errors.h"

namespace mmm::worklists::http {

struct GuardedServer::Tls {
  struct ContextDeleter {
    void operator()(SSL_CTX* ssl_context) const { SSL_CTX_free(ssl_context); }
  };
  std::unique_ptr<SSL_CTX, ContextDeleter> context;
};

namespace {

using Clock = std::chrono::steady_clock;

struct SslDeleter {
  void operator()(SSL* ssl) const { SSL_free(ssl); }
};
using SslHandle = std::unique_ptr<SSL, SslDeleter>;

// The first queued OpenSSL error as text (and the queue emptied).
std::string openssl_error() {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "no detail from OpenSSL";
  std::array<char, 256> text{};
  ERR_error_string_n(code, text.data(), text.size());
  return text.data();
}

// Waits until the socket is ready for `events` or the deadline passes.
bool wait_for(socket_t sock, short events, Clock::time_point deadline) {
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd entry{sock, events, 0};
    const int ready = ::poll(&entry, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready > 0) return (entry.revents & (events | POLLHUP | POLLERR)) != 0;
    if (ready < 0 && errno != EINTR) return false;
  }
}

// What OpenSSL waits for after `result` of an SSL_* call on a non-blocking
// socket: POLLIN, POLLOUT, or 0 when the call failed for good.
short events_awaited(SSL* ssl, int result) {
  const int error = SSL_get_error(ssl, result);
  return error == SSL_ERROR_WANT_READ ? POLLIN : error == SSL_ERROR_WANT_WRITE ? POLLOUT : 0;
}

// One request's worth of a socket, in clear or through TLS: reads end at the
// request deadline or after `max_read_bytes`, writes at the response deadline
// (both return -1 then, which makes cpp-httplib drop the connection).
class DeadlineStream final : public httplib::Stream {
 public:
  DeadlineStream(socket_t sock, SSL* ssl, Clock::time_point read_deadline,
                 const ConnectionLimits& limits)
      : sock_(sock),
        ssl_(ssl),
        read_deadline_(read_deadline),
        response_deadline_(limits.response_deadline),
        max_read_bytes_(limits.max_header_bytes + limits.max_body_bytes) {}

  bool is_readable() const override {
    return buffered_ > consumed_ || wait_for(sock_, POLLIN, read_deadline_);
  }

  bool is_writable() const override { return wait_for(sock_, POLLOUT, write_deadline()); }

  ssize_t read(char* ptr, size_t size) override {
    if (consumed_ == buffered_) {
      if (total_read_ >= max_read_bytes_) return -1;
      const std::size_t room = std::min(buffer_.size(), max_read_bytes_ - total_read_);
      const ssize_t got = ssl_ != nullptr ? tls_read(room) : plain_read(room);
      if (got <= 0) return got;
      total_read_ += static_cast<std::size_t>(got);
      buffered_ = static_cast<std::size_t>(got);
      consumed_ = 0;
    }
    const std::size_t count = std::min(size, buffered_ - consumed_);
    std::copy_n(buffer_.data() + consumed_, count, ptr);
    consumed_ += count;
    return static_cast<ssize_t>(count);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (ssl_ != nullptr) return tls_write(ptr, size);
    if (!wait_for(sock_, POLLOUT, write_deadline())) return -1;
    ssize_t sent = 0;
    do {
      sent = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    } while (sent < 0 && errno == EINTR);
    return sent;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    address_of(&::getpeername, ip, port);
  }

  void get_local_ip_and_port(std::string& ip, int& port) const override {
    address_of(&::getsockname, ip, port);
  }

  socket_t socket() const override { return sock_; }

 private:
  using NameFunction = int (*)(int, sockaddr*, socklen_t*);

  ssize_t plain_read(std::size_t room) {
    if (!wait_for(sock_, POLLIN, read_deadline_)) return -1;
    ssize_t got = 0;
    do {
      got = ::recv(sock_, buffer_.data(), room, 0);
    } while (got < 0 && errno == EINTR);
    return got;
  }

  // The socket is non-blocking under TLS: OpenSSL says what it waits for.
  ssize_t tls_read(std::size_t room) {
    for (;;) {
      const int got = SSL_read(ssl_, buffer_.data(), static_cast<int>(room));
      if (got > 0) return got;
      if (SSL_get_error(ssl_, got) == SSL_ERROR_ZERO_RETURN) return 0;
      const short events = events_awaited(ssl_, got);
      if (events == 0 || !wait_for(sock_, events, read_deadline_)) {
        ERR_clear_error();
        return -1;
      }
    }
  }

  ssize_t tls_write(const char* ptr, std::size_t size) {
    const int chunk = static_cast<int>(std::min<std::size_t>(size, 1U << 20U));
    for (;;) {
      const int sent = SSL_write(ssl_, ptr, chunk);
      if (sent > 0) return sent;
      const short events = events_awaited(ssl_, sent);
      if (events == 0 || !wait_for(sock_, events, write_deadline())) {
        ERR_clear_error();
        return -1;
      }
    }
  }

  // The response deadline runs from the first write.
  Clock::time_point write_deadline() const {
    if (!writing_) {
      writing_ = true;
      write_started_ = Clock::now();
    }
    return write_started_ + response_deadline_;
  }

  void address_of(NameFunction name_of, std::string& ip, int& port) const {
    sockaddr_storage address{};
    socklen_t length = sizeof(address);
    ip.clear();
    port = 0;
    if (name_of(sock_, reinterpret_cast<sockaddr*>(&address), &length) != 0) return;
    std::array<char, INET6_ADDRSTRLEN> text{};
    if (address.ss_family == AF_INET) {
      const auto* v4 = reinterpret_cast<const sockaddr_in*>(&address);
      ::inet_ntop(AF_INET, &v4->sin_addr, text.data(), text.size());
      port = ntohs(v4->sin_port);
    } else if (address.ss_family == AF_INET6) {
      const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&address);
      ::inet_ntop(AF_INET6, &v6->sin6_addr, text.data(), text.size());
      port = ntohs(v6->sin6_port);
    }
    ip = text.data();
  }

  socket_t sock_;
  SSL* ssl_;
  Clock::time_point read_deadline_;
  std::chrono::milliseconds response_deadline_;
  std::size_t max_read_bytes_;
  std::size_t total_read_ = 0;
  std::array<char, 16384> buffer_{};
  std::size_t buffered_ = 0;
  std::size_t consumed_ = 0;
  mutable bool writing_ = false;
  mutable Clock::time_point write_started_;
};

// The TLS handshake on a non-blocking socket, within the deadline.
SslHandle accept_tls(SSL_CTX* context, socket_t sock, Clock::time_point deadline) {
  const int flags = ::fcntl(sock, F_GETFL, 0);
  if (flags < 0 || ::fcntl(sock, F_SETFL, flags | O_NONBLOCK) < 0) return nullptr;
  SslHandle ssl(SSL_new(context));
  if (!ssl || SSL_set_fd(ssl.get(), sock) != 1) return nullptr;
  for (;;) {
    const int done = SSL_accept(ssl.get());
    if (done == 1) return ssl;
    const short events = events_awaited(ssl.get(), done);
    if (events == 0 || !wait_for(sock, events, deadline)) {
      ERR_clear_error();
      return nullptr;
    }
  }
}

// A lingering close: the response is sent (FIN), what the client still sends
// is read and dropped for a moment, then the socket closes. Closing with
// unread input would send a reset, which can destroy the response before the
// client reads it (a refused oversize or chunked body).
void close_lingering(socket_t sock, std::size_t max_drain) {
  ::shutdown(sock, SHUT_WR);
  std::array<char, 4096> drain{};
  const Clock::time_point until = Clock::now() + std::chrono::milliseconds(200);
  std::size_t drained = 0;
  while (drained < max_drain && Clock::now() < until) {
    pollfd entry{sock, POLLIN, 0};
    if (::poll(&entry, 1, 50) <= 0) continue;
    const ssize_t got = ::recv(sock, drain.data(), drain.size(), 0);
    if (got <= 0) break;
    drained += static_cast<std::size_t>(got);
  }
  ::close(sock);
}

}  // namespace

GuardedServer::GuardedServer(ConnectionLimits limits) : limits_(limits) {
  const std::size_t workers = std::max<std::size_t>(limits_.workers, 1);
  new_task_queue = [workers] { return new httplib::ThreadPool(workers); };
  set_payload_max_length(limits_.max_body_bytes);
}

GuardedServer::~GuardedServer() = default;

void GuardedServer::use_tls(const std::filesystem::path& certificate,
                            const std::filesystem::path& key) {
  auto tls = std::make_unique<Tls>();
  tls->context.reset(SSL_CTX_new(TLS_server_method()));
  if (!tls->context) throw InvalidInputError("OpenSSL could not start: " + openssl_error());
  SSL_CTX* context = tls->context.get();
  SSL_CTX_set_min_proto_version(context, TLS1_2_VERSION);
  SSL_CTX_set_mode(context, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
  if (SSL_CTX_use_certificate_chain_file(context, certificate.c_str()) != 1) {
    throw IoError(certificate, "cannot be read as a PEM certificate (chain): " + openssl_error() +
                                   "; hint: give the server's certificate, PEM-encoded");
  }
  if (SSL_CTX_use_PrivateKey_file(context, key.c_str(), SSL_FILETYPE_PEM) != 1) {
    throw IoError(key, "cannot be read as a PEM private key: " + openssl_error() +
                           "; hint: give the unencrypted key of the certificate");
  }
  if (SSL_CTX_check_private_key(context) != 1) {
    throw IoError(key,
                  "is not the private key of " + certificate.string() + ": " + openssl_error());
  }
  tls_ = std::move(tls);
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
  const Clock::time_point deadline = Clock::now() + limits_.request_deadline;
  bool ok = false;
  SslHandle ssl;
  if (tls_) ssl = accept_tls(tls_->context.get(), sock, deadline);
  if (!tls_ || ssl) {
    DeadlineStream stream(sock, ssl.get(), deadline, limits_);
    bool connection_closed = false;
    // One request per connection (close_connection): a client cannot keep a
    // worker between requests.
    ok = process_request(stream, true, connection_closed, [](httplib::Request&) {});
  }
  if (ssl) {
    SSL_shutdown(ssl.get());
    ERR_clear_error();
    ssl.reset();
  }
  close_lingering(sock, limits_.max_body_bytes);
  return ok;
}

}  // namespace mmm::worklists::http
