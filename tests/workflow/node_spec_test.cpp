#include "workflow/node_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "workflow/node_registry.h"

namespace mmm::workflow {
namespace {

using ::testing::HasSubstr;

NodeSpec decimate_spec() {
  return NodeSpec{"decimate_mesh", 2, "Lower-resolution copy of a mesh"}
      .input<port::Mesh>("mesh", "Surface to simplify")
      .optional_input<port::Report>("hints", "Optional hints")
      .param<std::int64_t>("target_faces", 5000, "Faces to reach", {.min = 4})
      .param<double>("max_angle", 60.0, "Largest normal change", {.min = 0, .max = 180}, "deg")
      .param_enum("method", "quadric", {"quadric", "uniform"}, "Simplification method")
      .param<bool>("keep_boundary", true, "Keep boundary vertices")
      .output<port::Mesh>("decimated", "Simplified surface");
}

TEST(NodeSpecTest, DeclaresPortsAndParameters) {
  const NodeSpec spec = decimate_spec();
  EXPECT_EQ(spec.name(), "decimate_mesh");
  EXPECT_EQ(spec.version(), 2);
  ASSERT_EQ(spec.inputs().size(), 2U);
  EXPECT_TRUE(spec.inputs()[0].required);
  EXPECT_FALSE(spec.inputs()[1].required);
  EXPECT_EQ(spec.find_output("decimated")->type, PortType::kMesh);
  EXPECT_EQ(spec.find_param("max_angle")->unit, "deg");
  EXPECT_EQ(spec.find_param("target_faces")->type, ParamType::kInteger);
  EXPECT_EQ(spec.find_param("nope"), nullptr);
}

TEST(NodeSpecTest, ParameterChecksNameTheProblem) {
  const NodeSpec spec = decimate_spec();
  const ParamSpec& faces = *spec.find_param("target_faces");
  EXPECT_FALSE(faces.check(std::int64_t{10}).has_value());
  EXPECT_THAT(*faces.check(std::int64_t{2}), HasSubstr("outside the range [4, inf]"));
  EXPECT_THAT(*faces.check(2.5), HasSubstr("expects an integer"));
  const ParamSpec& angle = *spec.find_param("max_angle");
  EXPECT_FALSE(angle.check(std::int64_t{90}).has_value());  // integers are numbers
  EXPECT_THAT(*angle.check(std::nan("")), HasSubstr("finite"));
  EXPECT_THAT(*spec.find_param("method")->check(std::string("fast")),
              HasSubstr("one of {quadric, uniform}"));
  EXPECT_THAT(*spec.find_param("keep_boundary")->check(std::string("yes")),
              HasSubstr("true or false"));
}

TEST(NodeSpecTest, RejectsBadDeclarations) {
  EXPECT_THROW(NodeSpec("Bad-Name", 1, ""), InvalidInputError);
  EXPECT_THROW(NodeSpec("ok", 0, ""), InvalidInputError);
  EXPECT_THROW(decimate_spec().input<port::Mesh>("mesh", "again"), InvalidInputError);
  EXPECT_THROW(NodeSpec("ok", 1, "").param<double>("w", -1.0, "", {.min = 0}), InvalidInputError);
  EXPECT_THROW(NodeSpec("ok", 1, "").param_enum("m", "c", {"a", "b"}, ""), InvalidInputError);
}

TEST(NodeSpecTest, PortTypeNamesRoundTrip) {
  for (const PortTypeInfo& info : all_port_types()) {
    EXPECT_EQ(port_type_from_name(info.name), info.type);
    EXPECT_EQ(&port_type_info(info.type), &info);
  }
  EXPECT_FALSE(port_type_from_name("mesh").has_value());  // names are case-sensitive
}

TEST(NodeRegistryTest, FindsTypesAndSuggestsNames) {
  NodeRegistry registry;
  registry.add(decimate_spec(), [](NodeContext&) {});
  registry.add(NodeSpec{"load_mesh", 1, "Read a mesh file"}, [](NodeContext&) {});
  EXPECT_NE(registry.find("load_mesh"), nullptr);
  EXPECT_EQ(registry.find("load"), nullptr);
  EXPECT_THAT(registry.similar_names("decimate_meshes"), ::testing::ElementsAre("decimate_mesh"));
  EXPECT_THROW(registry.add(NodeSpec{"load_mesh", 3, ""}, [](NodeContext&) {}), InvalidInputError);
  ASSERT_EQ(registry.all().size(), 2U);
  EXPECT_EQ(registry.all()[0]->spec.name(), "decimate_mesh");  // sorted
}

}  // namespace
}  // namespace mmm::workflow
