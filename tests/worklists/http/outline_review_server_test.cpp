// The web API serves the outline review like the landmark station, through
// the node type's task behaviour: the submission's fields are taken from the
// request body by name, a body without them is a 400, a malformed verdict is
// rejected with reasons and a valid one is accepted.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"
#include "workflow/study/study.h"
#include "worklists/http/station_server.h"
#include "worklists/operators.h"
#include "worklists/outline_review_task.h"
#include "worklists/study_runner.h"

// Last (see worklists/http/guarded_server.h).
#include <httplib.h>

namespace mmm::worklists::http {
namespace {

using Json = nlohmann::json;
using namespace std::chrono_literals;

constexpr const char* kServedReviewWorkflow = R"yaml(mmm_workflow: 1
name: review
inputs:
  radiographs: {type: RadiographPair}
  atlas: {type: Atlas}
nodes:
  - {id: review, type: outline_review, inputs: {radiographs: study.radiographs, atlas: study.atlas}}
)yaml";

workflow::NodeRegistry served_review_registry() {
  workflow::NodeRegistry registry;
  registry.add<OutlineReviewStation>();
  return registry;
}

class OutlineReviewServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image::BiplanarOptions options;
    options.isocentre_mm = {45, 0, -400};   // the toy leg's middle
    options.detector_pixel_pitch_mm = 4.0;  // ~3 mm pixels: small images
    std::vector<image::RadiographFile> files;
    const test::ScratchDir& inputs = inputs_;
    for (const image::RadiographView& view : make_biplanar_views(options)) {
      write_png(image::GrayImage16(view.width, view.height), inputs / (view.name + ".png"));
      files.push_back({view, view.name + ".png"});
    }
    write_view_sidecar(inputs / "views.json", files);
    const std::filesystem::path pair = test::write_file(
        inputs / "pair.json",
        image::radiograph_pair_to_json_text(image::load_radiograph_pair(inputs / "views.json")));
    test::write_toy_leg(inputs / "atlas");
    const std::filesystem::path workflow_file =
        test::write_file(inputs / "wf.yaml", kServedReviewWorkflow);
    workflow::Study study = workflow::Study::create(
        root_ / "p1",
        {workflow_file,
         {{"radiographs", pair.string()}, {"atlas", (inputs / "atlas").string()}},
         {"test", "test"}},
        registry_);
    run_study_with_tasks(study, {.jobs = 1, .provenance = {"test", "test"}});
    token_ = add_operator(root_.path(), "ana");
    ServerOptions server;
    server.root = root_.path();
    server.port = 0;
    server.sweep_interval = 0ms;
    server.mmm_version = "test";
    server_ = std::make_unique<StationServer>(std::move(server), registry_);
    runner_ = std::thread([this] { server_->run(); });
  }

  void TearDown() override {
    if (server_) server_->stop();
    if (runner_.joinable()) runner_.join();
  }

  // {status, JSON body} of a request with the operator's token.
  std::pair<int, Json> call(const std::string& method, const std::string& path,
                            const Json& body = Json::object()) {
    httplib::Client client("127.0.0.1", server_->port());
    const httplib::Headers headers = {{"Authorization", "Bearer " + token_}};
    const httplib::Result result =
        method == "GET" ? client.Get(path, headers)
                        : client.Post(path, headers, body.dump(), "application/json");
    if (!result) return {0, nullptr};
    return {result->status, Json::parse(result->body, nullptr, false)};
  }

  test::ScratchDir inputs_{"outline-review-server-inputs"};
  test::ScratchDir root_{"outline-review-server"};
  workflow::NodeRegistry registry_ = served_review_registry();
  std::string token_;
  std::unique_ptr<StationServer> server_;
  std::thread runner_;
};

TEST_F(OutlineReviewServerTest, TheApiTakesTheVerdictsFieldsRejectsAndAccepts) {
  const auto [listed, worklist] = call("GET", "/api/worklist");
  ASSERT_EQ(listed, 200);
  ASSERT_EQ(worklist["tasks"].size(), 1U);
  const std::string id = worklist["tasks"][0]["id"];
  const auto [shown, task] = call("GET", "/api/tasks/" + id);
  ASSERT_EQ(shown, 200);
  const Json& request = task["task"]["request"];
  EXPECT_EQ(request["kind"], "outline_review");
  const Json first = request["bones"][1]["outlines"]["frontal"][0][0];
  const Json correction = {
      {"bone", request["bones"][1]["name"]},
      {"view", "frontal"},
      {"points", Json::array({Json::array({first[0].get<double>() + 1, first[1].get<double>()})})}};
  const auto [claimed, claim] = call("POST", "/api/tasks/" + id + "/claim");
  EXPECT_EQ(claimed, 200) << claim;

  const auto [previewed, preview] =
      call("POST", "/api/tasks/" + id + "/preview",
           {{"decision", "correct"}, {"corrections", Json::array({correction})}});
  ASSERT_EQ(previewed, 200);
  EXPECT_TRUE(preview["reasons"].empty()) << preview;
  EXPECT_EQ(preview["values"]["format"], "mmm-outline-corrections");

  const auto [wrong, error] = call("POST", "/api/tasks/" + id + "/submit", {{"landmarks", {}}});
  EXPECT_EQ(wrong, 400);
  EXPECT_NE(error["error"].get<std::string>().find("\"decision\", \"corrections\""),
            std::string::npos)
      << error;

  Json bad = correction;
  bad["view"] = "oblique";
  const auto [rejected, outcome] =
      call("POST", "/api/tasks/" + id + "/submit",
           {{"decision", "correct"}, {"corrections", Json::array({bad})}});
  ASSERT_EQ(rejected, 200);
  EXPECT_FALSE(outcome["accepted"].get<bool>());
  EXPECT_NE(outcome["reasons"].dump().find("one of the views"), std::string::npos) << outcome;

  EXPECT_EQ(call("POST", "/api/tasks/" + id + "/claim").first, 200);
  const auto [accepted, verdict] = call("POST", "/api/tasks/" + id + "/submit",
                                        {{"decision", "correct"},
                                         {"corrections", Json::array({correction})},
                                         {"reason", "not a field of it"}});
  ASSERT_EQ(accepted, 200);
  EXPECT_TRUE(verdict["accepted"].get<bool>()) << verdict;
  EXPECT_EQ(verdict["task"]["result"]["corrections"][0]["points_px"].size(), 1U);
  EXPECT_FALSE(verdict["task"]["submission"].contains("reason")) << "the body's own field";
}

}  // namespace
}  // namespace mmm::worklists::http
