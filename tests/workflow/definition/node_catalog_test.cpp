#include "workflow/definition/node_catalog.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/workflow/definition/test_node_types.h"

namespace mmm::workflow {
namespace {

using ::testing::HasSubstr;

TEST(NodeCatalogTest, JsonHoldsPortsAndParamsInDeclarationOrder) {
  const NodeRegistry registry = test::make_test_registry();
  const nlohmann::json json = node_spec_json(registry.find("decimate_mesh")->spec);
  EXPECT_EQ(json["name"], "decimate_mesh");
  EXPECT_EQ(json["version"], 1);
  EXPECT_EQ(json["inputs"][0], nlohmann::json({{"name", "mesh"},
                                               {"type", "Mesh"},
                                               {"required", true},
                                               {"description", "Surface to simplify"}}));
  EXPECT_EQ(json["params"][0]["name"], "target_faces");
  EXPECT_EQ(json["params"][0]["default"], 5000);
  EXPECT_TRUE(json["params"][0]["min"].is_number_integer());
  EXPECT_FALSE(json["params"][0].contains("max"));  // unbounded
  EXPECT_EQ(json["params"][1]["unit"], "deg");
  EXPECT_EQ(json["params"][1]["max"], 180.0);
  const nlohmann::json load = node_spec_json(registry.find("load_mesh")->spec);
  EXPECT_EQ(load["params"][0]["choices"], nlohmann::json({"stl", "obj", "ply", "off", "vtp"}));
}

TEST(NodeCatalogTest, TextShowsRangesUnitsChoicesAndManualNodes) {
  const NodeRegistry registry = test::make_test_registry();
  const std::string decimate = node_spec_text(registry.find("decimate_mesh")->spec);
  EXPECT_THAT(decimate, ::testing::StartsWith("decimate_mesh (version 1)\n"));
  EXPECT_THAT(decimate, HasSubstr("(default 5000, range [4, inf])"));
  EXPECT_THAT(decimate, HasSubstr("(default 60 deg, range [1, 180])"));
  EXPECT_THAT(node_spec_text(registry.find("load_mesh")->spec),
              HasSubstr("(default stl, one of {stl, obj, ply, off, vtp})"));
  const std::string pick = node_spec_text(registry.find("pick_landmarks")->spec);
  EXPECT_THAT(pick, HasSubstr("(version 1, manual)"));
  EXPECT_THAT(pick, HasSubstr("previous              LandmarkSet optional"));
}

TEST(NodeCatalogTest, RegistryJsonListsTypesPortTypesAndTheSchema) {
  const nlohmann::json json = registry_json(test::make_test_registry());
  ASSERT_EQ(json["node_types"].size(), 5U);
  EXPECT_EQ(json["node_types"][0]["name"], "decimate_mesh");  // sorted by name
  EXPECT_EQ(json["port_types"].size(), all_port_types().size());
  EXPECT_EQ(json["schema"], "schemas/workflow.schema.yaml");
}

}  // namespace
}  // namespace mmm::workflow
