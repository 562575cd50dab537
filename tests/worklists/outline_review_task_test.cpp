// The outline review station's task cycle in process, through the same
// generic task code as the landmark station: a study pauses at the review,
// operators accept the bone outlines or submit corrections (rejected with
// reasons when malformed), review and corrections follow the same rules, the
// accepted value is the canonical OutlineCorrections artifact a downstream
// node reads, and the audit trail verifies.

#include "worklists/outline_review_task.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/image/outline_corrections.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"
#include "workflow/run/run_study.h"
#include "workflow/study/execution_records.h"
#include "worklists/audit_trail.h"
#include "worklists/audit_verify.h"
#include "worklists/study_runner.h"
#include "worklists/task_actions.h"
#include "worklists/task_store.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using workflow::Study;

// Every reason, one per line (readable in a failure message).
std::string all_reasons(const std::vector<std::string>& reasons) {
  std::string text;
  for (const std::string& reason : reasons) text += reason + "\n";
  return text;
}

workflow::NodeRegistry make_review_registry() {
  workflow::NodeRegistry registry;
  registry.add<OutlineReviewStation>();
  // Downstream: reads the verdict as the fitting node will.
  registry.add(workflow::NodeSpec{"count_points", 1, "Number of correction points"}
                   .input<workflow::port::OutlineCorrections>("corrections", "The verdict")
                   .output<workflow::port::Number>("count", "How many points"),
               [](workflow::NodeContext& context) {
                 const image::OutlineCorrections verdict = image::read_outline_corrections(
                     context.input_bytes("corrections"), "input 'corrections'");
                 std::size_t count = 0;
                 for (const image::OutlineCorrection& c : verdict.corrections) {
                   count += c.points_px.size();
                 }
                 context.set_output("count", Json(count).dump());
               });
  return registry;
}

constexpr const char* kReviewWorkflow = R"yaml(mmm_workflow: 1
name: review
inputs:
  radiographs: {type: RadiographPair}
  atlas: {type: Atlas}
  patient: {type: String, default: P001}
nodes:
  - {id: review, type: outline_review, inputs: {radiographs: study.radiographs, atlas: study.atlas, patient: study.patient}}
  - {id: count, type: count_points, inputs: {corrections: review.corrections}}
)yaml";

class OutlineReviewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image::BiplanarOptions options;
    options.isocentre_mm = {45, 0, -400};   // the toy leg's middle
    options.detector_pixel_pitch_mm = 4.0;  // ~3 mm pixels: small images
    std::vector<image::RadiographFile> files;
    for (const image::RadiographView& view : make_biplanar_views(options)) {
      write_png(image::GrayImage16(view.width, view.height), root_ / (view.name + ".png"));
      files.push_back({view, view.name + ".png"});
    }
    write_view_sidecar(root_ / "views.json", files);
    const std::string pair =
        image::radiograph_pair_to_json_text(image::load_radiograph_pair(root_ / "views.json"));
    const fs::path pair_file = test::write_file(root_ / "pair.json", pair);
    test::write_toy_leg(root_ / "atlas");
    const fs::path workflow_file = test::write_file(root_ / "wf.yaml", kReviewWorkflow);
    Study::create(dir_,
                  {workflow_file,
                   {{"radiographs", pair_file.string()}, {"atlas", (root_ / "atlas").string()}},
                   {"test", "test"}},
                  registry_);
  }

  Study open() { return Study::open(dir_, registry_); }

  StudyRunResult run(Study& study) {
    return run_study_with_tasks(study, {.jobs = 1, .provenance = {"test", "test"}});
  }

  std::string pause(Study& study) {
    const StudyRunResult result = run(study);
    EXPECT_EQ(result.summary->outcome, workflow::RunOutcome::kWaiting);
    EXPECT_EQ(result.opened.size(), 1U);
    return result.opened.empty() ? std::string() : result.opened.front().id;
  }

  // The accepted verdict's bytes (the review node's output artifact).
  static std::string accepted_artifact(Study& study) {
    const auto execution = workflow::last_done_execution(study.database(), "review");
    EXPECT_TRUE(execution.has_value());
    if (!execution) return {};
    EXPECT_EQ(execution->outputs.at("corrections").type, workflow::PortType::kOutlineCorrections);
    return study.artifacts().get(execution->outputs.at("corrections").hash);
  }

  // Corrections near the first point of a bone's outline in a view.
  static Json correction(const Json& request, const std::string& bone, const std::string& view,
                         int count) {
    for (const Json& entry : request["bones"]) {
      if (entry["name"] != bone) continue;
      const Json first = entry["outlines"][view][0][0];
      Json points = Json::array();
      for (int k = 0; k < count; ++k) {
        points.push_back({first[0].get<double>() + 1.5, first[1].get<double>() + k});
      }
      return {{"bone", bone}, {"view", view}, {"points", points}};
    }
    return nullptr;
  }

  const Actor ana_{"ana", "test"};
  const Actor ben_{"ben", "test"};
  test::ScratchDir root_{"outline-review"};
  fs::path dir_ = root_ / "study";
  workflow::NodeRegistry registry_ = make_review_registry();
};

TEST_F(OutlineReviewTest, TheTaskShowsEveryBonesOutlineInEveryView) {
  Study study = open();
  const std::string id = pause(study);
  const Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.node_type, "outline_review");
  EXPECT_EQ(task.request["kind"], "outline_review");
  EXPECT_EQ(task.request["patient"], "P001");
  EXPECT_EQ(task.request["level"], "lod1");
  EXPECT_EQ(task.request["images"].size(), 2U);
  EXPECT_EQ(task.request["radiographs"], study.inputs().at("radiographs").hash);
  EXPECT_EQ(task.request["atlas"], study.inputs().at("atlas").hash);
  std::set<std::string> bones;
  std::set<std::string> colours;
  for (const Json& bone : task.request["bones"]) {
    bones.insert(bone["name"].get<std::string>());
    colours.insert(bone["colour"].get<std::string>());
    for (const Json& view : task.request["views"]) {
      const Json& polylines = bone["outlines"][view["name"].get<std::string>()];
      ASSERT_FALSE(polylines.empty()) << bone["name"] << " in " << view["name"];
      for (const Json& polyline : polylines) {
        EXPECT_GE(polyline.size(), 2U);
        for (const Json& p : polyline) {
          // The toy leg lies inside both fields of view.
          EXPECT_GE(p[0].get<double>(), 0.0);
          EXPECT_LE(p[0].get<double>(), view["width"].get<double>());
          EXPECT_GE(p[1].get<double>(), 0.0);
          EXPECT_LE(p[1].get<double>(), view["height"].get<double>());
        }
      }
    }
  }
  EXPECT_EQ(bones, (std::set<std::string>{"femur_r", "patella_r", "pelvis", "talus_r", "tibia_r"}));
  EXPECT_EQ(colours.size(), bones.size()) << "one colour per bone";
}

TEST_F(OutlineReviewTest, AcceptingRecordsTheCanonicalVerdictAndTheStudyResumes) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  const SubmitOutcome outcome = submit_task(study, id, ana_, {{"decision", "accept"}});
  ASSERT_TRUE(outcome.accepted) << ::testing::PrintToString(outcome.reasons);
  image::OutlineCorrections expected;
  expected.decision = image::OutlineDecision::kAccept;
  expected.radiographs = study.inputs().at("radiographs").hash;
  expected.atlas = study.inputs().at("atlas").hash;
  EXPECT_EQ(accepted_artifact(study), image::outline_corrections_to_json_text(expected));
  EXPECT_EQ(outcome.values["decision"], "accept");

  const StudyRunResult resumed = run(study);
  EXPECT_EQ(resumed.summary->outcome, workflow::RunOutcome::kDone);
  EXPECT_THAT(resumed.summary->executed, ElementsAre("count"));
  EXPECT_EQ(Json::parse(study.artifacts().get(
                workflow::last_done_execution(study.database(), "count")->outputs["count"].hash)),
            0);
}

TEST_F(OutlineReviewTest, CorrectionsAreRecordedSortedWithTheirPoints) {
  Study study = open();
  const std::string id = pause(study);
  const Json request = find_task(study.database(), id)->request;
  const Json tibia = correction(request, "tibia_r", "lateral", 3);
  const Json femur = correction(request, "femur_r", "frontal", 2);
  claim_task(study, id, ana_);
  const SubmitOutcome outcome = submit_task(
      study, id, ana_, {{"decision", "correct"}, {"corrections", Json::array({tibia, femur})}});
  ASSERT_TRUE(outcome.accepted) << ::testing::PrintToString(outcome.reasons);
  const image::OutlineCorrections verdict =
      image::read_outline_corrections(accepted_artifact(study), "the accepted verdict");
  EXPECT_EQ(verdict.decision, image::OutlineDecision::kCorrect);
  ASSERT_EQ(verdict.corrections.size(), 2U);
  EXPECT_EQ(verdict.corrections[0].bone, "femur_r");  // sorted by bone
  EXPECT_EQ(verdict.corrections[0].view, "frontal");
  ASSERT_EQ(verdict.corrections[0].points_px.size(), 2U);
  EXPECT_EQ(verdict.corrections[0].points_px[1].x(), femur["points"][1][0].get<double>());
  EXPECT_EQ(verdict.corrections[0].points_px[1].y(), femur["points"][1][1].get<double>());
  EXPECT_EQ(verdict.corrections[1].bone, "tibia_r");
  EXPECT_EQ(verdict.corrections[1].points_px.size(), 3U);
  EXPECT_EQ(verdict.atlas, request["atlas"]);

  // The same corrections in another order give the same bytes.
  const workflow::ManualEvaluation again = evaluate_outline_review(
      request, {{"decision", "correct"}, {"corrections", Json::array({femur, tibia})}});
  ASSERT_TRUE(again.reasons.empty());
  EXPECT_EQ(again.outputs.at("corrections").bytes, accepted_artifact(study));

  EXPECT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
  EXPECT_EQ(Json::parse(study.artifacts().get(
                workflow::last_done_execution(study.database(), "count")->outputs["count"].hash)),
            5);
}

TEST_F(OutlineReviewTest, MalformedSubmissionsAreRejectedWithReasonsNeverThrown) {
  Study study = open();
  const std::string id = pause(study);
  const Json request = find_task(study.database(), id)->request;
  const Json good = correction(request, "femur_r", "frontal", 2);
  const auto with = [&](const char* key, const Json& value) {
    Json entry = good;
    entry[key] = value;
    return Json{{"decision", "correct"}, {"corrections", Json::array({entry})}};
  };
  Json many = Json::array();
  for (int k = 0; k < 201; ++k) many.push_back({10.0, 10.0 + (k % 100)});
  Json too_many_in_all = Json::array();
  for (const Json& bone : request["bones"]) {
    for (const char* view : {"frontal", "lateral"}) {
      Json points = Json::array();
      for (int k = 0; k < 200; ++k) points.push_back({10.0, 10.0 + (k % 100)});
      too_many_in_all.push_back({{"bone", bone["name"]}, {"view", view}, {"points", points}});
    }
  }
  too_many_in_all.push_back(too_many_in_all[0]);
  too_many_in_all.back()["bone"] = "femur_r";
  const std::vector<std::pair<Json, std::string>> cases = {
      {Json::array(), "must be an object"},
      {Json{{"decision", "maybe"}}, R"('decision' must be "accept" or "correct")"},
      {Json::object(), "'decision' must be"},
      {Json{{"decision", "accept"}, {"extra", 1}}, "unknown field 'extra'"},
      {Json{{"decision", "accept"}, {"corrections", Json::array({good})}}, "must be empty"},
      {Json{{"decision", "correct"}}, "non-empty list"},
      {Json{{"decision", "correct"}, {"corrections", Json::array()}}, "non-empty list"},
      {Json{{"decision", "correct"}, {"corrections", Json::array({1})}},
       "corrections[0]: expected"},
      {with("bone", "femur_l"), "one of the atlas's bones (pelvis, femur_r"},
      {with("view", "oblique"), "one of the views (frontal, lateral)"},
      {with("points", Json::array()), "non-empty list of [u, v]"},
      {with("points", Json::array({{1.0}})), "points[0]: must be [u, v]"},
      {with("points", Json::array({{"a", 1.0}})), "points[0]: must be [u, v]"},
      {with("points", Json::array({{-1.0, 5.0}})), "lies outside view 'frontal'"},
      {with("points", Json::array({{5.0, 1e9}})), "lies outside view 'frontal'"},
      {with("points", many), "201 points, at most 200"},
      {with("colour", "red"), "unknown field 'colour'"},
      {Json{{"decision", "correct"}, {"corrections", Json::array({good, good})}},
       "corrected twice"},
      {Json{{"decision", "correct"}, {"corrections", too_many_in_all}}, "at most 2000"},
  };
  for (const auto& [submission, reason] : cases) {
    workflow::ManualEvaluation evaluation;
    ASSERT_NO_THROW(evaluation = evaluate_outline_review(request, submission)) << submission;
    EXPECT_THAT(all_reasons(evaluation.reasons), HasSubstr(reason)) << submission;
    EXPECT_TRUE(evaluation.outputs.empty()) << submission;
  }
  // Non-finite numbers cannot come through JSON text but can through the API.
  const Json nan = with("points", Json::array({{std::nan(""), 5.0}}));
  EXPECT_THAT(all_reasons(evaluate_outline_review(request, nan).reasons),
              HasSubstr("must be finite"));

  // Through the task: rejected, back to open, with every reason.
  claim_task(study, id, ana_);
  const SubmitOutcome outcome = submit_task(study, id, ana_, with("view", "oblique"));
  EXPECT_FALSE(outcome.accepted);
  EXPECT_THAT(all_reasons(outcome.reasons), HasSubstr("one of the views"));
  const Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kOpen);
  EXPECT_FALSE(task.rejection_reasons.empty());
}

TEST_F(OutlineReviewTest, ReviewNeedsASecondOperator) {
  Study study = open();
  study.set_param("review", "review", "true");
  const std::string id = pause(study);
  EXPECT_EQ(find_task(study.database(), id)->request["review"], true);
  claim_task(study, id, ana_);
  const SubmitOutcome submitted = submit_task(study, id, ana_, {{"decision", "accept"}});
  EXPECT_TRUE(submitted.awaiting_review);
  EXPECT_FALSE(submitted.accepted);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kSubmitted);
  try {
    accept_task(study, id, ana_);
    FAIL() << "the submitter reviewed their own verdict";
  } catch (const TaskError& error) {
    EXPECT_THAT(error.what(), HasSubstr("rule: four eyes"));
  }
  EXPECT_EQ(run(study).summary->outcome, workflow::RunOutcome::kWaiting);
  EXPECT_TRUE(accept_task(study, id, ben_).accepted);
  EXPECT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
}

TEST_F(OutlineReviewTest, ACorrectionNeedsAReasonIsAuditedAndTheTrailVerifies) {
  Study study = open();
  const std::string id = pause(study);
  const Json request = find_task(study.database(), id)->request;
  claim_task(study, id, ana_);
  ASSERT_TRUE(submit_task(study, id, ana_, {{"decision", "accept"}}).accepted);
  ASSERT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
  const Json corrected = {
      {"decision", "correct"},
      {"corrections", Json::array({correction(request, "talus_r", "frontal", 4)})}};
  EXPECT_THROW(submit_task(study, id, ben_, corrected), TaskError) << "no reason";
  EXPECT_THROW(submit_task(study, id, ben_, corrected, "  "), TaskError) << "a blank reason";
  const SubmitOutcome outcome = submit_task(study, id, ben_, corrected, "talus edge is lower");
  ASSERT_TRUE(outcome.accepted) << ::testing::PrintToString(outcome.reasons);
  EXPECT_TRUE(outcome.correction);
  const StudyRunResult rerun = run(study);
  EXPECT_THAT(rerun.summary->executed, ElementsAre("count"));
  EXPECT_EQ(Json::parse(study.artifacts().get(
                workflow::last_done_execution(study.database(), "count")->outputs["count"].hash)),
            4);

  std::vector<std::string> actions;
  for (const AuditEntry& entry : read_audit(study.database())) {
    actions.push_back(entry.action);
    EXPECT_EQ(entry.images.size(), 2U) << "the hashes of the images shown";
    if (entry.action == "correct") {
      EXPECT_EQ(entry.operator_name, "ben");
      EXPECT_EQ(entry.reason, "talus edge is lower");
      EXPECT_EQ(entry.before["decision"], "accept");
      EXPECT_EQ(entry.after["decision"], "correct");
    }
  }
  EXPECT_THAT(actions, ElementsAre("open", "claim", "submit", "accept", "submit", "correct"));
  const AuditVerification verification = verify_audit(study.database(), study.dir());
  EXPECT_TRUE(verification.intact);
}

}  // namespace
}  // namespace mmm::worklists
