// The manual node types of mmm: each carries its task behaviour (what its
// tasks show and how a submission is evaluated), so the worklist, the audit
// trail, the commands and the web server need no knowledge of any of them;
// a manual type without one is refused at registration.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "core/errors.h"
#include "nodes/registry.h"
#include "workflow/definition/node_catalog.h"
#include "worklists/outline_review_task.h"

namespace mmm::nodes {
namespace {

using ::testing::HasSubstr;

TEST(ManualNodesTest, EveryManualNodeTypeCarriesItsTaskBehaviour) {
  const workflow::NodeRegistry registry = make_node_registry();
  std::set<std::string> manual;
  std::set<std::string> kinds;
  for (const workflow::NodeType* type : registry.all()) {
    if (!type->spec.is_manual()) {
      EXPECT_TRUE(type->task.empty()) << type->spec.name();
      continue;
    }
    manual.insert(type->spec.name());
    EXPECT_TRUE(type->task.complete()) << type->spec.name();
    EXPECT_TRUE(kinds.insert(type->task.kind).second)
        << type->spec.name() << ": the kind '" << type->task.kind << "' is taken";
  }
  EXPECT_EQ(manual, (std::set<std::string>{"landmark_station", "outline_review"}));
  EXPECT_EQ(kinds, (std::set<std::string>{"landmarks", "outline_review"}));
}

TEST(ManualNodesTest, AManualTypeWithoutBehaviourIsRefusedAtRegistration) {
  workflow::NodeRegistry registry;
  const auto nothing = [](workflow::NodeContext&) {};
  try {
    registry.add(workflow::NodeSpec{"approve", 1, "A person approves"}
                     .output<workflow::port::Bool>("ok", "Approved")
                     .manual(),
                 nothing);
    FAIL() << "a manual node type without task behaviour was registered";
  } catch (const InvalidInputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("'approve' is manual but has no complete task behaviour"));
  }
  workflow::ManualTaskBehaviour partial = worklists::OutlineReviewStation::task_behaviour();
  partial.evaluate = nullptr;
  EXPECT_THROW(registry.add(worklists::OutlineReviewStation::spec(),
                            &worklists::OutlineReviewStation::run, partial),
               InvalidInputError);
  EXPECT_THROW(
      registry.add(workflow::NodeSpec{"compute", 1, "Computes"}.output<workflow::port::Bool>(
                       "ok", "Computed"),
                   nothing, worklists::OutlineReviewStation::task_behaviour()),
      InvalidInputError)
      << "a computing node type has no tasks";
  EXPECT_EQ(registry.all().size(), 0U);
}

// Golden spec: a change of a port, a parameter or a default must show here.
TEST(ManualNodesTest, OutlineReviewSpecIsPinned) {
  EXPECT_EQ(workflow::node_spec_json(worklists::OutlineReviewStation::spec()).dump(2), R"json({
  "description": "Operator checks the atlas bones' outlines projected onto the two radiographs: accepts them, or marks where the true edges lie",
  "inputs": [
    {
      "description": "The patient's calibrated frontal and lateral views",
      "name": "radiographs",
      "required": true,
      "type": "RadiographPair"
    },
    {
      "description": "The bones fitted to the radiographs (their outlines are shown), e.g. by fit_bone_outlines",
      "name": "atlas",
      "required": true,
      "type": "Atlas"
    },
    {
      "description": "Patient identifier, shown to the operator",
      "name": "patient",
      "required": false,
      "type": "String"
    }
  ],
  "manual": true,
  "name": "outline_review",
  "outputs": [
    {
      "description": "The verdict: accepted as they are, or edge points per bone and view (pixels)",
      "name": "corrections",
      "type": "OutlineCorrections"
    }
  ],
  "params": [
    {
      "default": false,
      "description": "A second operator must accept each submission (four-eyes principle)",
      "name": "review",
      "type": "bool"
    },
    {
      "default": "Check each bone's outline against the radiographs in both views. If every outline follows its bone's edge, accept. Otherwise click on the true edge near a misplaced outline (the nearest outline picks the bone; points go to that bone in that view), then submit the corrections. Use window/level to see the bone edges.",
      "description": "Shown to the operator",
      "name": "instructions",
      "type": "string"
    },
    {
      "default": "lod1",
      "description": "The atlas mesh level whose outlines are shown (a coarse level keeps the outlines light; every bone must have it)",
      "name": "level",
      "type": "string"
    }
  ],
  "version": 1
})json");
}

}  // namespace
}  // namespace mmm::nodes
