// Cohorts (worklists/cohort.h, cohort_patients.h, root_gc.h): a patients
// file checked row by row, studies created under one root sharing one
// store, their status from the databases, and garbage collection that
// removes only what no study references.

#include "worklists/cohort.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/store/shared_store.h"
#include "workflow/store/study_lock.h"
#include "worklists/cohort_patients.h"
#include "worklists/root_gc.h"
#include "worklists/study_runner.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

workflow::NodeRegistry make_cohort_registry() {
  workflow::NodeRegistry registry;
  registry.add(workflow::NodeSpec{"join_files", 1, "Both files, one after the other"}
                   .input<workflow::port::File>("first", "A file")
                   .input<workflow::port::File>("second", "Another")
                   .output<workflow::port::File>("joined", "Both"),
               [](workflow::NodeContext& context) {
                 context.set_output("joined",
                                    context.input_bytes("first") + context.input_bytes("second"));
               });
  registry.add(workflow::NodeSpec{"fail_when", 1, "Fails when its number is 1"}
                   .input<workflow::port::Number>("number", "0 or 1")
                   .output<workflow::port::Number>("same", "The number"),
               [](workflow::NodeContext& context) {
                 if (context.input_bytes("number").starts_with("1")) {
                   throw InvalidInputError("the number is 1");
                 }
                 context.set_output("same", context.input_bytes("number"));
               });
  return registry;
}

constexpr const char* kCohortWorkflow = R"yaml(mmm_workflow: 1
name: cohort
inputs:
  atlas: {type: File}
  scan: {type: File}
  number: {type: Number, default: 0}
nodes:
  - {id: join, type: join_files, inputs: {first: study.atlas, second: study.scan}}
  - {id: check, type: fail_when, inputs: {number: study.number}}
outputs: {joined: join.joined}
)yaml";

struct FileIdentity {
  ino_t inode = 0;
  nlink_t links = 0;
};
FileIdentity identity_of(const fs::path& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return {info.st_ino, info.st_nlink};
}

class CohortTest : public ::testing::Test {
 protected:
  CohortTest() {
    workflow_ = test::write_file(scratch_ / "wf.yaml", kCohortWorkflow);
    atlas_ = test::write_file(scratch_ / "atlas.bin", std::string(200'000, 'a'));
    for (const char* id : {"p1", "p2", "p3"}) {
      test::write_file(scratch_ / "in" / id / "scan.bin", std::string("scan of ") + id);
    }
  }

  fs::path write_csv(const std::string& text) {
    return test::write_file(scratch_ / "in" / "patients.csv", text);
  }

  CohortCreateResult create(const fs::path& csv) {
    return create_cohort(root_, {workflow_, csv, {{"atlas", atlas_.string()}}, {"t", "t"}},
                         registry_);
  }

  std::string problems_of(const std::string& csv_text) {
    try {
      (void)create(write_csv(csv_text));
    } catch (const std::exception& error) {
      return error.what();
    }
    return "no error";
  }

  void run(const std::string& id) {
    workflow::Study study = workflow::Study::open(root_ / id, registry_);
    (void)run_study_with_tasks(study, {.jobs = 1, .provenance = {"t", "t"}});
  }

  workflow::NodeRegistry registry_ = make_cohort_registry();
  test::ScratchDir scratch_{"cohort"};
  fs::path root_ = scratch_ / "root";
  fs::path workflow_;
  fs::path atlas_;
};

TEST_F(CohortTest, StudiesShareWhatIsIdenticalAndKeepTheirOwn) {
  const CohortCreateResult result = create(write_csv(
      "id,scan,number\r\np1,p1/scan.bin,0\r\n# a comment\r\n\r\np2,\"p2/scan.bin\",\r\n"));
  EXPECT_THAT(result.created, ElementsAre("p1", "p2"));
  EXPECT_EQ(result.store, root_ / workflow::kSharedStoreFolder);
  // The atlas is stored once: both studies link the shared store's file.
  workflow::Study p1 = workflow::Study::open(root_ / "p1", registry_);
  workflow::Study p2 = workflow::Study::open(root_ / "p2", registry_);
  const std::string atlas = p1.inputs().at("atlas").hash;
  EXPECT_EQ(p2.inputs().at("atlas").hash, atlas);
  const FileIdentity shared = identity_of(root_ / workflow::kSharedStoreFolder /
                                          workflow::ArtifactStore::relative_path_of(atlas));
  EXPECT_EQ(shared.links, 3U);
  EXPECT_EQ(identity_of(p2.artifacts().path_of(atlas)).inode, shared.inode);
  EXPECT_NE(p1.inputs().at("scan").hash, p2.inputs().at("scan").hash);

  // Created again: nothing is touched, new rows are added.
  const CohortCreateResult again = create(write_csv("id,scan\np1,p1/scan.bin\np3,p3/scan.bin\n"));
  EXPECT_THAT(again.created, ElementsAre("p3"));
  EXPECT_THAT(again.existing, ElementsAre("p1"));
}

TEST_F(CohortTest, EveryBadRowIsReportedWithItsLineAndNothingIsCreated) {
  const std::string message = problems_of(
      "id,scan,number\n"
      "p1,p1/scan.bin,0\n"
      ".hidden,p2/scan.bin,0\n"
      "p1,p3/scan.bin,0\n"
      "p4,p4/missing.bin,0\n"
      "p5,p1/scan.bin,lots\n"
      "p6,,0\n"
      "p7,p1/scan.bin\n");
  EXPECT_THAT(message, HasSubstr("6 problem(s), nothing was created"));
  EXPECT_THAT(message, HasSubstr("line 3: id '.hidden' is not a folder name"));
  EXPECT_THAT(message, HasSubstr("line 4: id 'p1' is used by an earlier row"));
  EXPECT_THAT(message, HasSubstr("line 5: input 'scan': "));
  EXPECT_THAT(message, HasSubstr("line 6: "));
  EXPECT_THAT(message, HasSubstr("line 7: input 'scan' is empty and has no default"));
  EXPECT_THAT(message, HasSubstr("line 8: 2 fields, the header has 3"));
  EXPECT_FALSE(fs::exists(root_ / "p1"));
  EXPECT_FALSE(fs::exists(root_ / workflow::kSharedStoreFolder));

  EXPECT_THAT(problems_of("id,scna\np1,p1/scan.bin\n"),
              AllOf(HasSubstr("column 'scna' is not an input of the workflow"),
                    HasSubstr("did you mean 'scan'")));
  EXPECT_THAT(problems_of("scan\np1/scan.bin\n"), HasSubstr("no column 'id'"));
  EXPECT_THAT(problems_of("id,scan\np1,\"p1/scan.bin\n"), HasSubstr("line 2: a quoted field"));
  EXPECT_THAT(problems_of(""), HasSubstr("no header"));
}

TEST_F(CohortTest, StatusCountsEachStudysStateAndNamesFailures) {
  (void)create(write_csv("id,scan,number\np1,p1/scan.bin,0\np2,p2/scan.bin,1\np3,p3/scan.bin,0\n"));
  run("p1");
  run("p2");
  const CohortStatus status = cohort_status(root_);
  ASSERT_EQ(status.studies.size(), 3U);
  for (const CohortStudyState& study : status.studies) {
    SCOPED_TRACE(study.study + ": " + study.state + " " + study.detail);
  }
  ASSERT_EQ(status.counts.size(), 3U) << status.studies[0].state << " " << status.studies[1].state
                                      << " " << status.studies[2].state;
  EXPECT_EQ(status.counts.at("done"), 1);
  EXPECT_EQ(status.counts.at("failed"), 1);
  EXPECT_EQ(status.counts.at("created"), 1);
  EXPECT_EQ(status.studies[1].study, "p2");
  EXPECT_THAT(status.studies[1].detail, HasSubstr("check: "));
  EXPECT_THAT(status.studies[1].detail, HasSubstr("the number is 1"));
}

TEST_F(CohortTest, GarbageCollectionRemovesOnlyWhatNoStudyReferences) {
  (void)create(write_csv("id,scan\np1,p1/scan.bin\np2,p2/scan.bin\n"));
  run("p1");
  run("p2");
  const GcOptions now{.apply = false, .grace = std::chrono::seconds(0)};
  GcReport report = collect_garbage(root_, now);
  EXPECT_EQ(report.studies, 2U);
  EXPECT_TRUE(report.study_blobs.empty());
  EXPECT_TRUE(report.shared_blobs.empty());

  // A blob p1 stored but never recorded (a node's output superseded, say),
  // and one both studies stored: only the first is garbage.
  workflow::Study p1 = workflow::Study::open(root_ / "p1", registry_);
  const std::string orphan = p1.artifacts().put("nobody refers to this");
  report = collect_garbage(root_, now);
  ASSERT_EQ(report.study_blobs.size(), 1U);
  EXPECT_EQ(report.study_blobs[0].path, p1.artifacts().path_of(orphan));
  ASSERT_EQ(report.shared_blobs.size(), 1U) << "its shared copy goes with it";
  EXPECT_EQ(report.freed_bytes, 21U);
  EXPECT_TRUE(p1.artifacts().contains(orphan)) << "a dry run removes nothing";

  // Within the grace period it is young: kept.
  EXPECT_TRUE(collect_garbage(root_, {.apply = true}).study_blobs.empty());
  EXPECT_TRUE(p1.artifacts().contains(orphan));

  // A study a runner holds is not touched.
  {
    std::optional<workflow::StudyLock> lock = workflow::StudyLock::try_acquire(root_ / "p1");
    ASSERT_TRUE(lock);
    report = collect_garbage(root_, {.apply = true, .grace = std::chrono::seconds(0)});
    EXPECT_THAT(report.busy_studies, ElementsAre("p1"));
    EXPECT_TRUE(p1.artifacts().contains(orphan));
  }
  report = collect_garbage(root_, {.apply = true, .grace = std::chrono::seconds(0)});
  EXPECT_EQ(report.study_blobs.size(), 1U);
  EXPECT_FALSE(p1.artifacts().contains(orphan));
  EXPECT_FALSE(fs::exists(root_ / workflow::kSharedStoreFolder /
                          workflow::ArtifactStore::relative_path_of(orphan)));
  // Everything the studies reference is still there and intact; running
  // again reuses it all.
  for (const char* id : {"p1", "p2"}) {
    workflow::Study study = workflow::Study::open(root_ / id, registry_);
    for (const auto& [name, input] : study.inputs()) {
      EXPECT_TRUE(study.artifacts().verify(input.hash)) << id << " " << name;
    }
    const StudyRunResult again = run_study_with_tasks(study, {.jobs = 1, .provenance = {"t", "t"}});
    ASSERT_TRUE(again.summary);
    EXPECT_TRUE(again.summary->executed.empty()) << id;
  }
}

TEST(CohortCsvTest, QuotesCommasAndLineEndings) {
  const std::vector<CsvRecord> records =
      parse_csv("a,b\r\n\"x, y\",\"say \"\"hi\"\"\"\n\"two\nlines\",z", "t.csv");
  ASSERT_EQ(records.size(), 3U);
  EXPECT_THAT(records[1].fields, ElementsAre("x, y", "say \"hi\""));
  EXPECT_THAT(records[2].fields, ElementsAre("two\nlines", "z"));
  EXPECT_EQ(records[2].line, 3);
}

}  // namespace
}  // namespace mmm::worklists
