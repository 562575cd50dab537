#pragma once
// What one connection to the operator web UI may take (guarded_server.h).

#include <chrono>
#include <cstddef>

namespace mmm::worklists::http {

struct ConnectionLimits {
  // The whole request (request line, headers, body) must arrive within this.
  std::chrono::milliseconds request_deadline{10000};
  // The client must take the whole response within this (a radiograph's
  // pixels are tens of megabytes).
  std::chrono::milliseconds response_deadline{120000};
  std::size_t max_header_bytes = std::size_t{64} << 10U;
  // A submission is a few kilobytes; anything much larger is a mistake.
  std::size_t max_body_bytes = std::size_t{1} << 20U;
  // Connections served at the same time.
  std::size_t workers = 32;
};

}  // namespace mmm::worklists::http
