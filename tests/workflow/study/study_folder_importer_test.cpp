// A folder given for a File input that a folder importer takes (e.g. a DICOM
// series): the study stores what the importer makes of it and not the path,
// and refuses a folder no importer takes, naming the importers.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "workflow/study/study.h"

namespace mmm::workflow {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::SizeIs;

// Takes a folder holding at least one "*.part" file; stores the sorted
// contents of those files, one per line.
FolderImporter parts_importer() {
  return {"parts joining",
          [](const fs::path& folder) {
            return std::ranges::any_of(fs::directory_iterator(folder), [](const auto& entry) {
              return entry.path().extension() == ".part";
            });
          },
          [](const fs::path& folder) {
            std::vector<std::string> parts;
            for (const auto& entry : fs::directory_iterator(folder)) {
              if (entry.path().extension() == ".part")
                parts.push_back(test::read_text(entry.path()));
            }
            std::sort(parts.begin(), parts.end());
            std::string joined;
            for (const std::string& part : parts) joined += part + "\n";
            return joined;
          }};
}

NodeRegistry make_parts_registry() {
  NodeRegistry registry;
  registry.add(NodeSpec{"use_file", 1, "Reads a file"}
                   .input<port::File>("file", "Any file")
                   .output<port::Report>("report", "JSON report"),
               [](NodeContext&) {});
  registry.add_folder_importer(parts_importer());
  return registry;
}

constexpr const char* kPartsWorkflow = R"yaml(mmm_workflow: 1
name: folder_importer
inputs:
  image: {type: File, description: A file or a folder of parts}
nodes:
  - {id: use, type: use_file, inputs: {file: study.image}}
outputs: {report: use.report}
)yaml";

class StudyFolderImporterTest : public ::testing::Test {
 protected:
  StudyFolderImporterTest() {
    test::write_file(folder_ / "b.part", "second");
    test::write_file(folder_ / "a.part", "first");
    test::write_file(folder_ / "notes.txt", "not a part");
  }

  Study create(const fs::path& given) {
    const auto workflow = test::write_file(scratch_ / "wf.yaml", kPartsWorkflow);
    return Study::create(scratch_ / "study", {workflow, {{"image", given.string()}}, {"t", "t"}},
                         registry_);
  }

  std::string stored(Study& study) {
    return study.artifacts().get(study.inputs().at("image").hash);
  }

  NodeRegistry registry_ = make_parts_registry();
  test::ScratchDir scratch_{"folder-importer"};
  fs::path folder_ = scratch_ / "exam";
};

TEST_F(StudyFolderImporterTest, AFolderAnImporterTakesIsStoredAsItConvertsIt) {
  Study study = create(folder_);
  EXPECT_EQ(stored(study), "first\nsecond\n");
  const StudyInputRecord record = study.inputs().at("image");
  EXPECT_TRUE(record.is_file);
  // The path is not kept: importers keep out what identifies a patient, and
  // an export's folder names often do.
  EXPECT_EQ(record.given, "(parts joining; the path is not kept)");
  EXPECT_EQ(record.given.find("exam"), std::string::npos);
}

TEST_F(StudyFolderImporterTest, AnImportedFolderIsReplacedByGivingItAgainNotByRefresh) {
  Study study = create(folder_);
  test::write_file(folder_ / "c.part", "third");
  fs::last_write_time(folder_, fs::last_write_time(folder_) + std::chrono::seconds(5));
  EXPECT_THAT(study.refresh_file_inputs(), IsEmpty());
  EXPECT_EQ(stored(study), "first\nsecond\n");
  EXPECT_TRUE(study.set_input("image", folder_.string()));
  EXPECT_EQ(stored(study), "first\nsecond\nthird\n");
  EXPECT_FALSE(study.set_input("image", folder_.string()));
}

TEST_F(StudyFolderImporterTest, AFileThatAnImporterNowTakesForgetsItsPathOnRefresh) {
  const fs::path plain = test::write_file(scratch_ / "plain.txt", "plain text");
  registry_.add_file_importer({"upper-casing",
                               [](std::string_view head) { return head.starts_with("UPPER"); },
                               [](std::string_view bytes, const fs::path&) {
                                 std::string text(bytes);
                                 for (char& c : text) c = static_cast<char>(std::toupper(c));
                                 return text;
                               }});
  Study study = create(plain);
  EXPECT_EQ(study.inputs().at("image").given, plain.string());
  test::write_file(plain, "UPPER and lower");
  fs::last_write_time(plain, fs::last_write_time(plain) + std::chrono::seconds(5));
  const std::vector<std::string> changes = study.refresh_file_inputs();
  ASSERT_THAT(changes, SizeIs(1));
  EXPECT_THAT(changes[0], HasSubstr("(upper-casing; the path is not kept) has new content"));
  EXPECT_EQ(changes[0].find("plain.txt"), std::string::npos);
  EXPECT_EQ(stored(study), "UPPER AND LOWER");
  EXPECT_EQ(study.inputs().at("image").given, "(upper-casing; the path is not kept)");
}

TEST_F(StudyFolderImporterTest, AFolderNoImporterTakesIsRefusedNamingTheImporters) {
  const fs::path other = scratch_ / "other";
  test::write_file(other / "notes.txt", "nothing to import");
  try {
    (void)create(other);
    FAIL() << "no error";
  } catch (const IoError& error) {
    EXPECT_THAT(error.what(), HasSubstr("study input 'image' (File)"));
    EXPECT_THAT(error.what(), HasSubstr("folders that an importer takes (parts joining)"));
    EXPECT_THAT(error.what(), HasSubstr("--input image=PATH"));
  }
  EXPECT_FALSE(fs::exists(scratch_ / "study"));
}

TEST_F(StudyFolderImporterTest, AnImporterThatFailsRefusesTheStudy) {
  registry_.add_folder_importer({"failing", [](const fs::path&) { return true; },
                                 [](const fs::path& folder) -> std::string {
                                   throw IoError(folder, "cannot be converted");
                                 }});
  const fs::path other = scratch_ / "other";
  test::write_file(other / "notes.txt", "taken by the failing importer");
  EXPECT_THROW((void)create(other), IoError);
  EXPECT_FALSE(fs::exists(scratch_ / "study"));
}

TEST(NodeRegistryFolderImporterTest, AnImporterWithoutItsFunctionsIsRefused) {
  NodeRegistry registry;
  EXPECT_THROW(registry.add_folder_importer({"half", nullptr, nullptr}), InvalidInputError);
  EXPECT_EQ(registry.folder_importer_names(), "");
  EXPECT_EQ(registry.folder_importer_for(fs::temp_directory_path()), nullptr);
}

}  // namespace
}  // namespace mmm::workflow
