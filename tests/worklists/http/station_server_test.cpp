#include "worklists/http/station_server.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/node_registry.h"

namespace mmm::worklists::http {
namespace {

ServerOptions options_for(const std::filesystem::path& root, int port) {
  ServerOptions options;
  options.root = root;
  options.port = port;
  options.sweep_interval = std::chrono::milliseconds(0);
  return options;
}

// cpp-httplib's default SO_REUSEPORT let a second `mmm serve` bind the port
// of a running one silently; it must fail and name the address.
TEST(StationServerTest, ASecondServerOnATakenPortIsAnErrorNamingTheAddress) {
  const test::ScratchDir dir("station-port");
  const workflow::NodeRegistry registry;
  const StationServer first(options_for(dir.path(), 0), registry);
  ASSERT_GT(first.port(), 0);
  try {
    const StationServer second(options_for(dir.path(), first.port()), registry);
    FAIL() << "a second server bound port " << first.port();
  } catch (const IoError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("cannot listen there"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace mmm::worklists::http
