// The operator web UI under hostile and heavy use, on loopback only and
// bounded in time: slow clients, refused bodies, many operators at once, and
// HTTPS with a certificate made for the test.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/node_registry.h"
#include "worklists/http/station_server.h"
#include "worklists/operators.h"

// Last (see worklists/http/guarded_server.h).
#include <httplib.h>

namespace mmm::worklists::http {
namespace {

using namespace std::chrono_literals;

// A raw TCP connection to the server, for requests no well-behaved client
// would send.
class RawConnection {
 public:
  explicit RawConnection(int port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  }
  ~RawConnection() { ::close(fd_); }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;
  RawConnection(RawConnection&&) = delete;
  RawConnection& operator=(RawConnection&&) = delete;

  [[nodiscard]] bool connected() const { return connected_; }

  // false once the server has closed the connection.
  bool send_text(const std::string& text) const {
    return ::send(fd_, text.data(), text.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(text.size());
  }

  // Whether the server closes the connection within `wait` (what it sends
  // before is read and dropped).
  bool closed_by_server(std::chrono::milliseconds wait) {
    const auto until = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < until) {
      pollfd entry{fd_, POLLIN, 0};
      if (::poll(&entry, 1, 50) <= 0) continue;
      std::array<char, 4096> buffer{};
      if (::recv(fd_, buffer.data(), buffer.size(), 0) <= 0) return true;
    }
    return false;
  }

  // What the server sent until it closed the connection or `wait` passed.
  std::string receive(std::chrono::milliseconds wait) {
    std::string out;
    const auto until = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < until) {
      pollfd entry{fd_, POLLIN, 0};
      if (::poll(&entry, 1, 50) <= 0) continue;
      std::array<char, 4096> buffer{};
      const ssize_t got = ::recv(fd_, buffer.data(), buffer.size(), 0);
      if (got <= 0) break;
      out.append(buffer.data(), static_cast<std::size_t>(got));
    }
    return out;
  }

 private:
  int fd_;
  bool connected_ = false;
};

class StationServerLoadTest : public ::testing::Test {
 protected:
  void start(ServerOptions options) {
    options.root = dir_.path();
    options.port = 0;
    options.sweep_interval = 0ms;
    server_ = std::make_unique<StationServer>(std::move(options), registry_);
    runner_ = std::thread([this] { server_->run(); });
  }

  void TearDown() override {
    if (server_) server_->stop();
    if (runner_.joinable()) runner_.join();
  }

  static ServerOptions small_limits() {
    ServerOptions options;
    options.limits.workers = 4;
    options.limits.request_deadline = 1000ms;
    return options;
  }

  test::ScratchDir dir_{"station-load"};
  const workflow::NodeRegistry registry_{};
  std::unique_ptr<StationServer> server_;
  std::thread runner_;
};

TEST_F(StationServerLoadTest, SlowClientsAreCutOffAndOperatorsAreStillAnswered) {
  const std::string token = add_operator(dir_.path(), "alice");
  start(small_limits());
  const int port = server_->port();

  // Three times as many slow clients as workers, each trickling a header
  // line every 200 ms for 3 s (three times the request deadline).
  constexpr int kSlowClients = 12;
  std::atomic<int> cut_off{0};
  std::vector<std::thread> slow;
  slow.reserve(kSlowClients);
  for (int i = 0; i < kSlowClients; ++i) {
    slow.emplace_back([port, &cut_off] {
      RawConnection connection(port);
      if (!connection.connected()) return;
      connection.send_text("GET /api/whoami HTTP/1.1\r\nHost: x\r\n");
      for (int line = 0; line < 15; ++line) {
        std::this_thread::sleep_for(200ms);
        if (!connection.send_text("X-Slow-" + std::to_string(line) + ": y\r\n")) {
          ++cut_off;
          return;
        }
      }
      // Closed by the server, the last sends may still succeed locally:
      // the end of the stream tells.
      if (connection.closed_by_server(3000ms)) ++cut_off;
    });
  }
  std::this_thread::sleep_for(300ms);

  // Six operators, three requests each, while the slow clients hold on.
  constexpr int kOperators = 6;
  constexpr int kRequests = 3;
  std::atomic<int> answered{0};
  std::vector<std::thread> operators;
  operators.reserve(kOperators);
  for (int i = 0; i < kOperators; ++i) {
    operators.emplace_back([port, &token, &answered] {
      httplib::Client client("127.0.0.1", port);
      client.set_connection_timeout(10s);
      client.set_read_timeout(10s);
      client.set_bearer_token_auth(token);
      for (int k = 0; k < kRequests; ++k) {
        const httplib::Result result = client.Get("/api/whoami");
        if (result && result->status == 200 &&
            result->body.find("\"alice\"") != std::string::npos) {
          ++answered;
        }
      }
    });
  }
  for (std::thread& thread : operators) thread.join();
  for (std::thread& thread : slow) thread.join();
  EXPECT_EQ(answered.load(), kOperators * kRequests);
  EXPECT_EQ(cut_off.load(), kSlowClients);
}

TEST_F(StationServerLoadTest, ChunkedBodiesAreRefusedBeforeAnythingIsRead) {
  const std::string token = add_operator(dir_.path(), "alice");
  start(small_limits());
  RawConnection connection(server_->port());
  ASSERT_TRUE(connection.connected());
  ASSERT_TRUE(
      connection.send_text("POST /api/tasks/abc/preview HTTP/1.1\r\nHost: x\r\n"
                           "Authorization: Bearer " +
                           token +
                           "\r\nTransfer-Encoding: chunked\r\n"
                           "Content-Type: application/json\r\n\r\n"));
  // A first chunk of 64 KiB; the server answers without waiting for more.
  connection.send_text("10000\r\n" + std::string(0x10000, '[') + "\r\n");
  const std::string answer = connection.receive(3000ms);
  EXPECT_EQ(answer.rfind("HTTP/1.1 411", 0), 0U) << answer.substr(0, 200);
  EXPECT_NE(answer.find("Content-Length"), std::string::npos) << answer;
}

TEST_F(StationServerLoadTest, OversizeBodiesAndRequestsWithoutATokenAreAnsweredFromTheHeaders) {
  const std::string token = add_operator(dir_.path(), "alice");
  start(small_limits());
  {
    // 2 MiB announced with a valid token: 413, the body never sent.
    RawConnection connection(server_->port());
    ASSERT_TRUE(connection.connected());
    connection.send_text(
        "POST /api/tasks/abc/submit HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer " + token +
        "\r\nContent-Length: 2097152\r\n\r\n");
    const std::string answer = connection.receive(3000ms);
    EXPECT_EQ(answer.rfind("HTTP/1.1 413", 0), 0U) << answer.substr(0, 200);
  }
  {
    // 500 KB announced without a token: 401 at once, the body never awaited.
    RawConnection connection(server_->port());
    ASSERT_TRUE(connection.connected());
    connection.send_text(
        "POST /api/tasks/abc/preview HTTP/1.1\r\nHost: x\r\nContent-Length: 500000\r\n\r\n");
    const std::string answer = connection.receive(3000ms);
    EXPECT_EQ(answer.rfind("HTTP/1.1 401", 0), 0U) << answer.substr(0, 200);
    EXPECT_NE(answer.find("no operator token"), std::string::npos) << answer;
  }
  {
    // A request line without end: cut at the header limit or the deadline.
    RawConnection connection(server_->port());
    ASSERT_TRUE(connection.connected());
    connection.send_text("GET /" + std::string(200000, 'a'));
    EXPECT_EQ(connection.receive(3000ms).find("200 OK"), std::string::npos);
  }
  // ... and the server still answers.
  httplib::Client client("127.0.0.1", server_->port());
  client.set_bearer_token_auth(token);
  const httplib::Result result = client.Get("/api/whoami");
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, 200);
}

// A self-signed certificate and its key (P-256), as PEM files.
void write_test_certificate(const std::filesystem::path& certificate,
                            const std::filesystem::path& key) {
  EVP_PKEY* pkey = EVP_EC_gen("P-256");
  ASSERT_NE(pkey, nullptr);
  X509* cert = X509_new();
  X509_set_version(cert, 2);
  ASN1_INTEGER_set(X509_get_serialNumber(cert), 1);
  X509_gmtime_adj(X509_getm_notBefore(cert), 0);
  X509_gmtime_adj(X509_getm_notAfter(cert), 3600);
  X509_set_pubkey(cert, pkey);
  X509_NAME* name = X509_get_subject_name(cert);
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC,
                             reinterpret_cast<const unsigned char*>("localhost"), -1, -1, 0);
  X509_set_issuer_name(cert, name);
  ASSERT_GT(X509_sign(cert, pkey, EVP_sha256()), 0);
  FILE* cert_file = std::fopen(certificate.c_str(), "w");
  ASSERT_NE(cert_file, nullptr);
  PEM_write_X509(cert_file, cert);
  std::fclose(cert_file);
  FILE* key_file = std::fopen(key.c_str(), "w");
  ASSERT_NE(key_file, nullptr);
  PEM_write_PrivateKey(key_file, pkey, nullptr, nullptr, 0, nullptr, nullptr);
  std::fclose(key_file);
  X509_free(cert);
  EVP_PKEY_free(pkey);
}

TEST_F(StationServerLoadTest, ServesHttpsWithTheGivenCertificateAndRefusesClearText) {
  const std::string token = add_operator(dir_.path(), "alice");
  const test::ScratchDir keys("station-tls");
  ASSERT_NO_FATAL_FAILURE(write_test_certificate(keys / "cert.pem", keys / "key.pem"));
  ServerOptions options = small_limits();
  options.tls_certificate = keys / "cert.pem";
  options.tls_key = keys / "key.pem";
  start(options);

  httplib::SSLClient secure("127.0.0.1", server_->port());
  secure.enable_server_certificate_verification(false);  // self-signed for the test
  secure.set_bearer_token_auth(token);
  const httplib::Result result = secure.Get("/api/whoami");
  ASSERT_TRUE(result) << httplib::to_string(result.error());
  EXPECT_EQ(result->status, 200);
  EXPECT_NE(result->body.find("\"alice\""), std::string::npos);

  httplib::Client clear("127.0.0.1", server_->port());
  clear.set_read_timeout(3s);
  clear.set_bearer_token_auth(token);
  const httplib::Result refused = clear.Get("/api/whoami");
  EXPECT_FALSE(refused && refused->status == 200);
}

TEST(StationServerTlsTest, AKeyThatIsNotTheCertificatesIsAnErrorNamingIt) {
  const test::ScratchDir dir("station-tls-mismatch");
  ASSERT_NO_FATAL_FAILURE(write_test_certificate(dir / "cert.pem", dir / "key.pem"));
  ASSERT_NO_FATAL_FAILURE(write_test_certificate(dir / "other.pem", dir / "other-key.pem"));
  const workflow::NodeRegistry registry;
  ServerOptions options;
  options.root = dir.path();
  options.port = 0;
  options.tls_certificate = dir / "cert.pem";
  options.tls_key = dir / "other-key.pem";
  try {
    const StationServer server(options, registry);
    FAIL() << "a mismatched key was accepted";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("other-key.pem"), std::string::npos) << error.what();
  }
  options.tls_key.clear();
  EXPECT_THROW(const StationServer server(options, registry), InvalidInputError);
}

}  // namespace
}  // namespace mmm::worklists::http
