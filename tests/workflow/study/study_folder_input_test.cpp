// Study inputs of type Atlas given as a folder (workflow/study/study.h): the
// store holds the folder's bundle (core/directory_bundle.h), and an edited
// folder is noticed and re-packed by refresh_file_inputs().

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "core/directory_bundle.h"
#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/host_and_time.h"
#include "workflow/study/study.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::SizeIs;

NodeRegistry make_registry() {
  NodeRegistry registry;
  registry.add(NodeSpec{"use_atlas", 1, "Reads an atlas and a file"}
                   .input<port::Atlas>("atlas", "An atlas")
                   .input<port::File>("file", "Any file")
                   .output<port::Report>("report", "JSON report"),
               [](NodeContext&) {});
  return registry;
}

constexpr const char* kWorkflow = R"yaml(mmm_workflow: 1
name: atlas_folder
description: One node that takes an atlas and a file
inputs:
  atlas:
    type: Atlas
    description: The generic atlas
  surface:
    type: File
    description: A surface file
nodes:
  - {id: use, type: use_atlas, inputs: {atlas: study.atlas, file: study.surface}}
outputs: {report: use.report}
)yaml";

class StudyFolderInputTest : public ::testing::Test {
 protected:
  StudyFolderInputTest() {
    test::write_file(atlas_ / "atlas.yaml", "mmm_atlas: 1\nname: tiny\n");
    test::write_file(atlas_ / "meshes/femur_r/full.ply", std::string("ply\n\0\1\2", 7));
    test::write_file(surface_, "solid s\nendsolid s\n");
  }

  Study create(const std::string& atlas_given, const std::string& surface_given) {
    const auto workflow = test::write_file(scratch_ / "wf.yaml", kWorkflow);
    return Study::create(
        scratch_ / "study",
        {workflow, {{"atlas", atlas_given}, {"surface", surface_given}}, {"test", "test"}},
        registry_);
  }

  std::string stored_atlas(Study& study) {
    return study.artifacts().get(study.inputs().at("atlas").hash);
  }

  NodeRegistry registry_ = make_registry();
  test::ScratchDir scratch_{"folder-input"};
  fs::path atlas_ = scratch_ / "atlas";
  fs::path surface_ = scratch_ / "surface.stl";
};

TEST_F(StudyFolderInputTest, AnAtlasFolderIsStoredAsItsBundle) {
  Study study = create(atlas_.string(), surface_.string());
  const StudyInputRecord record = study.inputs().at("atlas");
  EXPECT_TRUE(record.is_file);
  EXPECT_EQ(record.given, atlas_.string());
  EXPECT_EQ(stored_atlas(study), pack_directory(atlas_));
  // Stamp: the total size of the files in the folder.
  EXPECT_EQ(record.source_size, 24 + 7);
}

TEST_F(StudyFolderInputTest, AnEditedAtlasFolderIsRepackedOnRefreshOnce) {
  Study study = create(atlas_.string(), surface_.string());
  const std::string before = study.inputs().at("atlas").hash;

  test::write_file(atlas_ / "atlas.yaml", "mmm_atlas: 1\nname: edited\n");
  // Move the time on explicitly: the edit may fall in the same clock tick as
  // the creation on a coarse file system.
  fs::last_write_time(atlas_ / "atlas.yaml",
                      fs::last_write_time(atlas_ / "atlas.yaml") + std::chrono::seconds(5));
  const std::vector<std::string> changes = study.refresh_file_inputs();
  ASSERT_THAT(changes, SizeIs(1));
  EXPECT_THAT(changes[0], HasSubstr("study input 'atlas' changed"));
  const std::string after = study.inputs().at("atlas").hash;
  EXPECT_NE(after, before);
  EXPECT_EQ(stored_atlas(study), pack_directory(atlas_));

  EXPECT_THAT(study.refresh_file_inputs(), IsEmpty());
  EXPECT_EQ(study.inputs().at("atlas").hash, after);
}

TEST_F(StudyFolderInputTest, AFileAddedToTheFolderIsNoticed) {
  Study study = create(atlas_.string(), surface_.string());
  test::write_file(atlas_ / "meshes/femur_r/lod1.ply", "ply\n");
  EXPECT_THAT(study.refresh_file_inputs(), SizeIs(1));
  EXPECT_THAT(bundle_file_names(stored_atlas(study), "atlas"),
              ::testing::Contains("meshes/femur_r/lod1.ply"));
}

TEST_F(StudyFolderInputTest, ATouchedButUnchangedFolderIsNoChange) {
  Study study = create(atlas_.string(), surface_.string());
  const std::string before = study.inputs().at("atlas").hash;
  fs::last_write_time(atlas_ / "atlas.yaml",
                      fs::last_write_time(atlas_ / "atlas.yaml") + std::chrono::seconds(5));
  EXPECT_THAT(study.refresh_file_inputs(), IsEmpty());
  EXPECT_EQ(study.inputs().at("atlas").hash, before);
}

TEST_F(StudyFolderInputTest, APackedBundleFileIsTakenAsItIs) {
  const fs::path packed = test::write_file(scratch_ / "atlas.bundle", pack_directory(atlas_));
  Study study = create(packed.string(), surface_.string());
  EXPECT_EQ(stored_atlas(study), pack_directory(atlas_));
  // The folder and its packed file are the same value.
  EXPECT_FALSE(study.set_input("atlas", atlas_.string()));
}

TEST_F(StudyFolderInputTest, AFolderForAnotherTypeIsRefusedWithAHint) {
  try {
    (void)create(atlas_.string(), atlas_.string());
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("study input 'surface' (File)"));
    EXPECT_THAT(error.what(), HasSubstr("only Atlas inputs may be given as a folder"));
    EXPECT_THAT(error.what(), HasSubstr("--input surface=PATH"));
  }
  EXPECT_FALSE(fs::exists(scratch_ / "study"));
}

TEST_F(StudyFolderInputTest, AMissingAtlasFolderNamesTheFolderHint) {
  try {
    (void)create((scratch_ / "no_atlas").string(), surface_.string());
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("no such folder or file"));
    EXPECT_THAT(error.what(), HasSubstr("--input atlas=DIR"));
  }
}

TEST_F(StudyFolderInputTest, AnAtlasFolderThatCannotBePackedIsAnIoError) {
  fs::create_symlink(surface_, atlas_ / "outside.stl");
  EXPECT_THROW((void)create(atlas_.string(), surface_.string()), IoError);
  EXPECT_FALSE(fs::exists(scratch_ / "study"));
}

// A 2 GB input used to be copied whole into the study before anything
// looked at its size.
TEST_F(StudyFolderInputTest, AnInputOverTheLimitIsRefusedBeforeAnythingIsCopied) {
  const fs::path big = scratch_ / "big.stl";
  test::write_file(big, "solid s\n");
  fs::resize_file(big, static_cast<std::uintmax_t>(kMaxStudyInputBytes) + 1);  // sparse
  try {
    (void)create(atlas_.string(), big.string());
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("big.stl"));
    EXPECT_THAT(error.what(), HasSubstr("a study input is at most 1073741824 (1 GiB)"));
  }
  EXPECT_FALSE(fs::exists(scratch_ / "study"));
  for (const auto& entry : fs::directory_iterator(scratch_.path())) {
    EXPECT_FALSE(entry.path().filename().string().starts_with(".study.creating-")) << entry.path();
  }
}

// A killed `study create` leaves its hidden staging folder; the next create
// of the same study removes it when its process is gone, and leaves those of
// a live process and of another machine alone.
TEST_F(StudyFolderInputTest, TheStagingFolderOfAKilledCreateIsRemovedByTheNextOne) {
  const std::string prefix = ".study.creating-";
  const fs::path dead = scratch_ / (prefix + "999999999-1-" + host_name());
  const fs::path live = scratch_ / (prefix + std::to_string(::getpid()) + "-2-" + host_name());
  const fs::path elsewhere = scratch_ / (prefix + "999999999-3-another-machine.example");
  for (const fs::path& staging : {dead, live, elsewhere}) {
    test::write_file(staging / "artifacts/blob", std::string(1000, 'x'));
  }
  (void)create(atlas_.string(), surface_.string());
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(elsewhere)) << "may belong to a create running on another machine";
}

}  // namespace
}  // namespace mmm::workflow
