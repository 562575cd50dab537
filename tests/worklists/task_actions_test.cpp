// The landmark station's task cycle in process: a study pauses at the
// station, a task opens, operators claim (racing), submit (rejected with
// reasons or accepted), correct, and the study resumes running exactly the
// downstream nodes; every action lands in the audit trail.

#include "worklists/task_actions.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <thread>

#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "tests/support/test_data.h"
#include "workflow/run/run_study.h"
#include "workflow/run/study_plan.h"
#include "workflow/store/study_lock.h"
#include "workflow/study/execution_records.h"
#include "worklists/audit_trail.h"
#include "worklists/audit_verify.h"
#include "worklists/landmark_task.h"
#include "worklists/study_runner.h"
#include "worklists/task_store.h"
#include "worklists/worklist.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using workflow::NodeState;
using workflow::Study;

workflow::NodeRegistry make_registry() {
  workflow::NodeRegistry registry;
  registry.add<LandmarkStation>();
  registry.add(workflow::NodeSpec{"count_landmarks", 1, "Number of landmarks"}
                   .input<workflow::port::LandmarkSet>("landmarks", "Landmarks")
                   .output<workflow::port::Number>("count", "How many"),
               [](workflow::NodeContext& context) {
                 const Json set = Json::parse(context.input_bytes("landmarks"));
                 context.set_output("count", Json(set["landmarks"].size()).dump());
               });
  return registry;
}

constexpr const char* kWorkflow = R"yaml(mmm_workflow: 1
name: station
inputs:
  radiographs: {type: RadiographPair}
  patient: {type: String, default: P001}
nodes:
  - {id: landmarks, type: landmark_station, inputs: {radiographs: study.radiographs, patient: study.patient}}
  - {id: count, type: count_landmarks, inputs: {landmarks: landmarks.landmarks}}
)yaml";

const Eigen::Vector3d kHead(90, 0, 900);
const Eigen::Vector3d kPatella(80, 30, 480);
const Eigen::Vector3d kAnkle(75, 0, 80);

class TaskActionsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image::BiplanarOptions options;
    options.isocentre_mm = {0, 0, 500};
    options.detector_pixel_pitch_mm = 4.0;  // ~3 mm pixels: small images
    const auto views = make_biplanar_views(options);
    std::vector<image::RadiographFile> files;
    for (const image::RadiographView& view : views) {
      write_png(image::GrayImage16(view.width, view.height), root_ / (view.name + ".png"));
      files.push_back({view, view.name + ".png"});
      views_.push_back(view);
    }
    write_view_sidecar(root_ / "views.json", files);
    const std::string pair =
        image::radiograph_pair_to_json_text(image::load_radiograph_pair(root_ / "views.json"));
    const fs::path pair_file = test::write_file(root_ / "pair.json", pair);
    const fs::path workflow_file = test::write_file(root_ / "wf.yaml", kWorkflow);
    Study::create(dir_, {workflow_file, {{"radiographs", pair_file.string()}}, {"test", "test"}},
                  registry_);
  }

  Study open() { return Study::open(dir_, registry_); }

  StudyRunResult run(Study& study) {
    return run_study_with_tasks(study, {.jobs = 1, .provenance = {"test", "test"}});
  }

  // The study paused at the station with its task open; returns the task id.
  std::string pause(Study& study) {
    const StudyRunResult result = run(study);
    EXPECT_EQ(result.summary->outcome, workflow::RunOutcome::kWaiting);
    EXPECT_EQ(result.opened.size(), 1U);
    return result.opened.empty() ? std::string() : result.opened.front().id;
  }

  Json pixel(const Eigen::Vector3d& point, const std::string& view) const {
    for (const image::RadiographView& v : views_) {
      if (v.name == view) {
        const Eigen::Vector2d uv = image::project(v, point);
        return {uv.x(), uv.y()};
      }
    }
    return nullptr;
  }

  Json submission(bool with_ankle = true) const {
    Json landmarks;
    landmarks["femoral_head_centre_r"] = {{"frontal", pixel(kHead, "frontal")},
                                          {"lateral", pixel(kHead, "lateral")}};
    landmarks["patella_centre_r"] = {{"frontal", pixel(kPatella, "frontal")},
                                     {"lateral", pixel(kPatella, "lateral")}};
    if (with_ankle) {
      landmarks["ankle_centre_r"] = {{"frontal", pixel(kAnkle, "frontal")},
                                     {"lateral", pixel(kAnkle, "lateral")}};
    }
    return {{"landmarks", landmarks}};
  }

  const Actor ana_{"ana", "test"};
  const Actor ben_{"ben", "test"};
  test::ScratchDir root_{"task-actions"};
  fs::path dir_ = root_ / "study";
  workflow::NodeRegistry registry_ = make_registry();
  std::vector<image::RadiographView> views_;
};

TEST_F(TaskActionsTest, TheStudyPausesAtTheStationAndResumesAfterAcceptance) {
  Study study = open();
  const std::string id = pause(study);
  Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kOpen);
  EXPECT_EQ(task.request["patient"], "P001");
  EXPECT_EQ(task.request["landmarks"].size(), 3U);
  EXPECT_EQ(task.request["images"].size(), 2U);
  // A second run opens no second task.
  EXPECT_TRUE(run(study).opened.empty());
  EXPECT_EQ(list_worklist(root_.path()).size(), 1U);

  claim_task(study, id, ana_);
  const SubmitOutcome outcome = submit_task(study, id, ana_, submission());
  ASSERT_TRUE(outcome.accepted) << ::testing::PrintToString(outcome.reasons);
  EXPECT_EQ(outcome.task.state, TaskState::kAccepted);
  EXPECT_EQ(outcome.task.assignee, "ana");
  for (const Json& landmark : outcome.values["landmarks"]) {
    for (const auto& [view, error] : landmark["reprojection_error_mm"].items()) {
      EXPECT_LT(error.get<double>(), 1e-6) << landmark["name"] << " " << view;
    }
  }
  const Json head = outcome.values["landmarks"][0]["position_mm"];
  EXPECT_NEAR(head[0].get<double>(), kHead.x(), 1e-6);
  EXPECT_NEAR(head[2].get<double>(), kHead.z(), 1e-6);

  const StudyRunResult resumed = run(study);
  EXPECT_EQ(resumed.summary->outcome, workflow::RunOutcome::kDone);
  EXPECT_THAT(resumed.summary->executed, ElementsAre("count"));
  EXPECT_TRUE(list_worklist(root_.path()).empty()) << "accepted tasks leave the worklist";
  WorklistFilter every;
  every.include_closed = true;
  EXPECT_EQ(list_worklist(root_.path(), every).size(), 1U);
}

TEST_F(TaskActionsTest, OfRacingClaimsExactlyOneWins) {
  Study study = open();
  const std::string id = pause(study);
  std::atomic<int> won{0};
  std::atomic<int> lost{0};
  std::vector<std::thread> operators;
  operators.reserve(6);
  for (int i = 0; i < 6; ++i) {
    operators.emplace_back([&, i] {
      Study own = open();  // its own database connection, as another process would have
      try {
        claim_task(own, id, {"op" + std::to_string(i), "test"});
        ++won;
      } catch (const TaskError&) {
        ++lost;
      }
    });
  }
  for (std::thread& thread : operators) thread.join();
  EXPECT_EQ(won.load(), 1);
  EXPECT_EQ(lost.load(), 5);
  const Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kClaimed);
  EXPECT_THAT(task.assignee, ::testing::StartsWith("op"));
}

TEST_F(TaskActionsTest, OnlyTheAssigneeReleasesOrSubmitsAndReassignMovesTheTask) {
  Study study = open();
  const std::string id = pause(study);
  EXPECT_THROW(submit_task(study, id, ana_, submission()), TaskError) << "not claimed";
  claim_task(study, id, ana_);
  EXPECT_THROW(claim_task(study, id, ben_), TaskError);
  EXPECT_THROW(release_task(study, id, ben_), TaskError);
  EXPECT_THROW(submit_task(study, id, ben_, submission()), TaskError);
  reassign_task(study, id, ana_, "ben");
  EXPECT_EQ(find_task(study.database(), id)->assignee, "ben");
  release_task(study, id, ben_);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kOpen);
  EXPECT_THROW(claim_task(study, id, {"not a name", "test"}), TaskError);
  EXPECT_THROW(cancel_task(study, id, ana_, ""), TaskError) << "a reason is required";
  cancel_task(study, id, ana_, "patient withdrew");
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kCancelled);
  EXPECT_THROW(claim_task(study, id, ana_), TaskError);
}

// Each rule of the validation, through the task: the submission is
// rejected with that reason and the task is open again.
struct RejectionCase {
  const char* name;
  std::function<void(Json&)> spoil;
  const char* expected;  // part of a reason
};

class TaskRejectionTest : public TaskActionsTest,
                          public ::testing::WithParamInterface<RejectionCase> {};

TEST_P(TaskRejectionTest, AnInvalidSubmissionIsRejectedWithItsReasonAndTheTaskReopens) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  Json spoiled = submission();
  GetParam().spoil(spoiled);
  const SubmitOutcome outcome = submit_task(study, id, ana_, spoiled);
  EXPECT_FALSE(outcome.accepted);
  ASSERT_FALSE(outcome.reasons.empty());
  std::string all;
  for (const std::string& reason : outcome.reasons) all += reason + "\n";
  EXPECT_THAT(all, HasSubstr(GetParam().expected));
  const Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kOpen);
  EXPECT_TRUE(task.assignee.empty());
  EXPECT_EQ(task.rejection_reasons, outcome.reasons);
  EXPECT_EQ(run(study).summary->outcome, workflow::RunOutcome::kWaiting) << "never fails the study";
}

INSTANTIATE_TEST_SUITE_P(
    EachRule, TaskRejectionTest,
    ::testing::Values(
        RejectionCase{"MissingRequired", [](Json& s) { s["landmarks"].erase("patella_centre_r"); },
                      "patella_centre_r"},
        RejectionCase{"OutsideTheImage",
                      [](Json& s) {
                        s["landmarks"]["ankle_centre_r"]["frontal"] = {-5.0, 100.0};
                      },
                      "outside"},
        RejectionCase{"ViewsDisagree",
                      [](Json& s) {
                        Json& uv = s["landmarks"]["patella_centre_r"]["lateral"];
                        uv[1] = uv[1].get<double>() + 10.0;  // 30 mm lower in one view
                      },
                      "reprojection"},
        RejectionCase{"MalformedPixel",
                      [](Json& s) { s["landmarks"]["ankle_centre_r"]["lateral"] = "here"; },
                      "two numbers"},
        RejectionCase{"UnknownLandmark",
                      [](Json& s) { s["landmarks"]["femoral_head_center_r"] = Json::object(); },
                      "femoral_head_center_r"},
        RejectionCase{"OrderSwapped",
                      [](Json& s) {
                        std::swap(s["landmarks"]["femoral_head_centre_r"],
                                  s["landmarks"]["patella_centre_r"]);
                      },
                      "above"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST_F(TaskActionsTest, ACorrectionNeedsAReasonSupersedesAndRerunsOnlyDownstream) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  ASSERT_TRUE(submit_task(study, id, ana_, submission(false)).accepted);
  ASSERT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
  EXPECT_THROW(submit_task(study, id, ben_, submission()), TaskError) << "no reason";
  const SubmitOutcome corrected = submit_task(study, id, ben_, submission(), "ankle centre added");
  ASSERT_TRUE(corrected.accepted);
  EXPECT_TRUE(corrected.correction);
  const StudyRunResult rerun = run(study);
  EXPECT_THAT(rerun.summary->executed, ElementsAre("count"));
  EXPECT_EQ(workflow::last_done_execution(study.database(), "count")->outputs.size(), 1U);
  EXPECT_EQ(Json::parse(study.artifacts().get(
                workflow::last_done_execution(study.database(), "count")->outputs["count"].hash)),
            3);
  // An invalid correction is rejected and the accepted values stay.
  Json bad = submission();
  bad["landmarks"].erase("femoral_head_centre_r");
  const SubmitOutcome refused = submit_task(study, id, ben_, bad, "try");
  EXPECT_FALSE(refused.accepted);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kAccepted);
  EXPECT_TRUE(run(study).summary->executed.empty());
}

TEST_F(TaskActionsTest, ReviewKeepsASubmissionUntilASecondOperatorAcceptsIt) {
  Study study = open();
  study.set_param("landmarks", "review", "true");
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  const SubmitOutcome submitted = submit_task(study, id, ana_, submission());
  EXPECT_TRUE(submitted.awaiting_review);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kSubmitted);
  EXPECT_THROW(accept_task(study, id, ana_), TaskError) << "not one's own work";
  reject_task(study, id, ben_, {"patella centre looks off"});
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kOpen);
  claim_task(study, id, ana_);
  submit_task(study, id, ana_, submission());
  EXPECT_TRUE(accept_task(study, id, ben_).accepted);
  EXPECT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
}

// Four eyes: reassigning the submitted task to someone else used to make
// its submitter an acceptable reviewer of their own values.
TEST_F(TaskActionsTest, TheSubmitterNeverReviewsWhoeverTheTaskIsAssignedTo) {
  Study study = open();
  study.set_param("landmarks", "review", "true");
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  ASSERT_TRUE(submit_task(study, id, ana_, submission()).awaiting_review);
  EXPECT_EQ(find_task(study.database(), id)->submitted_by, "ana");
  reassign_task(study, id, ana_, "ben");
  EXPECT_EQ(find_task(study.database(), id)->assignee, "ben");
  try {
    accept_task(study, id, ana_);
    FAIL() << "the submitter reviewed their own values";
  } catch (const TaskError& error) {
    EXPECT_THAT(error.what(), HasSubstr("rule: four eyes"));
  }
  EXPECT_THROW(reject_task(study, id, ana_, {"never mind"}), TaskError);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kSubmitted);
  EXPECT_TRUE(accept_task(study, id, ben_).accepted);
}

// A correction of a node that asks for review used to be applied at once.
TEST_F(TaskActionsTest, ACorrectionOfAReviewedNodeWaitsForASecondOperator) {
  Study study = open();
  study.set_param("landmarks", "review", "true");
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  submit_task(study, id, ana_, submission(false));
  ASSERT_TRUE(accept_task(study, id, ben_).accepted);
  ASSERT_EQ(run(study).summary->outcome, workflow::RunOutcome::kDone);
  const Json accepted = find_task(study.database(), id)->result;

  const SubmitOutcome pending = submit_task(study, id, ben_, submission(), "ankle centre added");
  EXPECT_TRUE(pending.awaiting_review);
  EXPECT_TRUE(pending.correction);
  EXPECT_FALSE(pending.accepted);
  Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kAccepted);
  EXPECT_EQ(task.result, accepted) << "the accepted values stay in force";
  EXPECT_EQ(task.pending_correction["by"], "ben");
  EXPECT_TRUE(run(study).summary->executed.empty()) << "nothing re-runs before the review";
  EXPECT_EQ(list_worklist(root_.path()).size(), 1U) << "the correction waits on the worklist";
  EXPECT_THROW(submit_task(study, id, ana_, submission(), "another"), TaskError)
      << "one correction at a time";
  EXPECT_THROW(accept_task(study, id, ben_), TaskError) << "four eyes for corrections too";

  const SubmitOutcome reviewed = accept_task(study, id, ana_);
  EXPECT_TRUE(reviewed.accepted);
  EXPECT_TRUE(reviewed.correction);
  task = *find_task(study.database(), id);
  EXPECT_TRUE(task.pending_correction.is_null());
  EXPECT_EQ(task.submitted_by, "ben");
  EXPECT_NE(task.result, accepted);
  EXPECT_THAT(run(study).summary->executed, ElementsAre("count"));

  // A rejected correction leaves the accepted values as they were.
  const Json current = task.result;
  ASSERT_TRUE(submit_task(study, id, ana_, submission(false), "ankle unsure").awaiting_review);
  reject_task(study, id, ben_, {"the ankle is clearly visible"});
  task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kAccepted);
  EXPECT_EQ(task.result, current);
  EXPECT_TRUE(task.pending_correction.is_null());
  EXPECT_TRUE(run(study).summary->executed.empty());
  EXPECT_TRUE(verify_audit(study.database(), study.dir()).intact);
}

TEST_F(TaskActionsTest, BlankReasonsAreNotReasons) {
  Study study = open();
  study.set_param("landmarks", "review", "true");
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  EXPECT_THROW(cancel_task(study, id, ana_, "   "), TaskError) << "cancel";
  submit_task(study, id, ana_, submission(false));
  EXPECT_THROW(reject_task(study, id, ben_, {"  "}), TaskError) << "reject";
  EXPECT_THROW(reject_task(study, id, ben_, {"fine", ""}), TaskError) << "every reason";
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kSubmitted);
  ASSERT_TRUE(accept_task(study, id, ben_).accepted);
  EXPECT_THROW(submit_task(study, id, ben_, submission(), " \t "), TaskError) << "correction";
  EXPECT_TRUE(find_task(study.database(), id)->pending_correction.is_null());
}

// Anyone could take over or cancel the task another operator had claimed.
TEST_F(TaskActionsTest, OnlyTheAssigneeOrASupervisorReleasesReassignsOrCancelsAClaimedTask) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  for (const auto& attempt : std::vector<std::function<void()>>{
           [&] { reassign_task(study, id, ben_, "ben"); }, [&] { release_task(study, id, ben_); },
           [&] { cancel_task(study, id, ben_, "taking over"); }}) {
    try {
      attempt();
      FAIL() << "ben acted on ana's task";
    } catch (const TaskError& error) {
      EXPECT_THAT(error.what(), HasSubstr("rule: assignee or supervisor"));
    }
  }
  Task task = *find_task(study.database(), id);
  EXPECT_EQ(task.state, TaskState::kClaimed);
  EXPECT_EQ(task.assignee, "ana");

  const Actor sue{"sue", "test", true};
  reassign_task(study, id, sue, "ben");
  EXPECT_EQ(find_task(study.database(), id)->assignee, "ben");
  const std::vector<AuditEntry> trail = read_audit(study.database());
  ASSERT_FALSE(trail.empty());
  EXPECT_EQ(trail.back().action, "reassign");
  EXPECT_EQ(trail.back().operator_name, "sue") << "the audit says who";
  release_task(study, id, ben_);
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kOpen);
}

// A copied study folder keeps its task ids: a full id then names two tasks,
// and no command may pick one of them silently.
TEST_F(TaskActionsTest, AnIdInTwoStudiesIsRefusedNamingThemAndStudySlashIdPicksOne) {
  Study study = open();
  const std::string id = pause(study);
  ASSERT_FALSE(id.empty());
  fs::copy(dir_, root_ / "copy", fs::copy_options::recursive);
  try {
    (void)locate_task(root_.path(), id);
    FAIL() << "an id in two studies was resolved";
  } catch (const InvalidInputError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("several studies"), std::string::npos) << what;
    EXPECT_NE(what.find("(study)"), std::string::npos) << what;
    EXPECT_NE(what.find("(copy)"), std::string::npos) << what;
    EXPECT_NE(what.find("STUDY/" + id), std::string::npos) << what;
  }
  EXPECT_THROW((void)locate_task(root_.path(), id.substr(0, 6)), InvalidInputError);
  EXPECT_EQ(locate_task(root_.path(), "copy/" + id).study, "copy");
  EXPECT_EQ(locate_task(root_.path(), "study/" + id.substr(0, 6)).study, "study");
  EXPECT_THROW((void)locate_task(root_.path(), "elsewhere/" + id), InvalidInputError);
}

TEST_F(TaskActionsTest, ReservedNamesCannotAct) {
  Study study = open();
  const std::string id = pause(study);
  for (const char* name : {"mmm", "System", "ROOT", "admin"}) {
    try {
      claim_task(study, id, {name, "test"});
      FAIL() << name << " claimed a task";
    } catch (const TaskError& error) {
      EXPECT_THAT(error.what(), HasSubstr("is reserved")) << name;
    }
  }
  EXPECT_EQ(find_task(study.database(), id)->state, TaskState::kOpen);
}

// An intact chain used to be reported "intact" however the tasks table and
// the accepted results had been edited, and with every entry deleted.
TEST_F(TaskActionsTest, VerifyCrossChecksTheTasksAndTheirResultsAgainstTheTrail) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  ASSERT_TRUE(submit_task(study, id, ana_, submission()).accepted);
  ASSERT_TRUE(verify_audit(study.database(), study.dir()).intact);
  const auto kinds = [&] {
    std::vector<AuditProblemKind> found;
    for (const AuditProblem& problem : verify_audit(study.database(), study.dir()).problems) {
      found.push_back(problem.kind);
    }
    return found;
  };

  // The femoral head moved 30 mm up in the tasks table.
  const Json accepted = find_task(study.database(), id)->result;
  Json forged = accepted;
  Json& z = forged["landmarks"][0]["position_mm"][2];
  z = z.get<double>() + 30.0;
  const auto set_result = [&](const Json& result) {
    study.database()
        .prepare("UPDATE tasks SET result_json = ? WHERE id = ?")
        .bind_text(1, result.dump())
        .bind_text(2, id)
        .step();
  };
  set_result(forged);
  EXPECT_THAT(kinds(), ElementsAre(AuditProblemKind::kValueMismatch));
  set_result(accepted);
  EXPECT_TRUE(verify_audit(study.database(), study.dir()).intact);

  // The stored result edited in place.
  const std::string hash =
      workflow::last_done_execution(study.database(), "landmarks")->outputs.at("landmarks").hash;
  const fs::path blob = study.artifacts().path_of(hash);
  const std::string original = test::read_text(blob);
  fs::permissions(blob, fs::perms::owner_write, fs::perm_options::add);
  test::write_file(blob, original + " ");
  EXPECT_THAT(kinds(), ElementsAre(AuditProblemKind::kArtifactChanged));
  test::write_file(blob, original);
  EXPECT_TRUE(verify_audit(study.database(), study.dir()).intact);

  // Every entry deleted (and the checkpoint with them).
  study.database().exec(
      "DROP TRIGGER IF EXISTS audit_no_update; DROP TRIGGER IF EXISTS audit_no_delete; "
      "DELETE FROM audit; DELETE FROM meta WHERE key = 'audit_head';");
  fs::remove(audit_checkpoint_path(study.dir()));
  const AuditVerification emptied = verify_audit(study.database(), study.dir());
  EXPECT_FALSE(emptied.intact);
  EXPECT_EQ(emptied.entries, 0);
  EXPECT_THAT(kinds(), ::testing::Contains(AuditProblemKind::kTaskUnaudited));
}

TEST_F(TaskActionsTest, ChangedInputsCancelTheOldTaskAndOpenANewOne) {
  Study study = open();
  const std::string first = pause(study);
  claim_task(study, first, ana_);
  study.set_param("landmarks", "reprojection_tolerance_mm", "5");
  const StudyRunResult result = run(study);
  ASSERT_EQ(result.opened.size(), 1U);
  EXPECT_NE(result.opened.front().id, first);
  EXPECT_EQ(find_task(study.database(), first)->state, TaskState::kCancelled);
}

TEST_F(TaskActionsTest, EveryActionIsAuditedAndTheTrailVerifies) {
  Study study = open();
  const std::string id = pause(study);
  claim_task(study, id, ana_);
  Json bad = submission();
  bad["landmarks"].erase("femoral_head_centre_r");
  submit_task(study, id, ana_, bad);
  claim_task(study, id, ana_);
  submit_task(study, id, ana_, submission());
  std::vector<std::string> actions;
  for (const AuditEntry& entry : read_audit(study.database())) {
    actions.push_back(entry.action);
    EXPECT_EQ(entry.task_id, id);
    EXPECT_EQ(entry.images.size(), 2U) << "the hashes of the images shown";
  }
  EXPECT_THAT(actions,
              ElementsAre("open", "claim", "submit", "reject", "claim", "submit", "accept"));
  EXPECT_TRUE(verify_audit(study.database(), study.dir()).intact);
}

}  // namespace
}  // namespace mmm::worklists
