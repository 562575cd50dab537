#include "core/atlas/atlas_recipe.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <string_view>

#include "core/errors.h"
#include "tests/support/test_data.h"

namespace mmm::atlas {
namespace {

using ::testing::HasSubstr;

// A small valid recipe; each malformed case below edits one piece of it.
// Line numbers (1-based) are quoted by the tests.
constexpr const char* kRecipe = R"(mmm_atlas_recipe: 1
name: tiny
opensim: {model: m.osim, geometry: Geometry}
midline: sacrum
lod_faces: [4000, 1000]
regions:
  - {name: pelvis, tags: [region]}
bones:
  - {name: sacrum, body: pelvis, file: sacrum.stl, region: pelvis}
  - {name: femur_r, body: femur_r, opensim_meshes: [femur_r.vtp]}
  - {name: tibia_r, body: tibia_r, file: tibia.stl}
registration:
  pelvis: {method: hip_and_sacrum, meshes: [sacrum.vtp], acetabulum: acetabulum.stl, sacrum: sacrum}
  femur_r: {method: head_and_condyles, meshes: [femur_r.vtp], head: head.stl, condyles: cond.stl}
  tibia_r: {method: surface, meshes: [tibia_r.vtp], targets: [tibia_r], joint_anchor: knee_r}
muscles:
  - {name: gluteus_r, file: glut.stl, action_lines: [glut_max1_r], architecture: fanned, region: pelvis}
landmarks:
  - {name: head_r, bone: femur_r, method: sphere_centre, file: head.stl}
  - {name: knee_r, bone: femur_r, method: joint_centre, joint: knee_r}
)";

// kRecipe with the first occurrence of `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  std::string text = kRecipe;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "the test's edit does not apply: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The message read_atlas_recipe throws for `text` (an IoError, checked), or
// "" when it reads.
std::string rejection(const std::string& text) {
  const test::ScratchDir dir("atlas_recipe");
  const auto file = test::write_file(dir / "recipe.yaml", text);
  try {
    (void)read_atlas_recipe(file);
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), file);
    std::string message = error.what();
    EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0U) << "what() starts with the path";
    return message;
  }
  return {};
}

const RecipeRegistration* registration_of(const AtlasRecipe& recipe, const std::string& body) {
  const auto it = std::ranges::find(recipe.registrations, body, &RecipeRegistration::body);
  return it == recipe.registrations.end() ? nullptr : &*it;
}

TEST(AtlasRecipeTest, DefaultRecipeReads) {
  const AtlasRecipe recipe =
      read_atlas_recipe(test::source_dir() / "schemas/recipes/vhf_right_leg.yaml");
  EXPECT_EQ(recipe.name, "vhf_right_leg");
  EXPECT_EQ(recipe.opensim.model, "gait2392/gait2392_thelen2003muscle.osim");
  EXPECT_EQ(recipe.opensim.geometry, "gait2392/Geometry");
  EXPECT_EQ(recipe.midline_bone, "sacrum");
  EXPECT_EQ(recipe.lod_faces, (std::vector<int>{4000, 1000}));
  EXPECT_EQ(recipe.regions.size(), 4U);
  EXPECT_EQ(recipe.bones.size(), 16U);
  EXPECT_EQ(recipe.registrations.size(), 6U);
  EXPECT_EQ(recipe.muscles.size(), 38U);  // 37 right-leg muscles + the mirrored left one
  EXPECT_EQ(recipe.landmarks.size(), 13U);
  for (const std::string_view required : kRequiredLandmarks) {
    EXPECT_TRUE(std::ranges::any_of(recipe.landmarks, [&](const RecipeLandmark& l) {
      return l.name == required;
    })) << required;
  }
  EXPECT_DOUBLE_EQ(recipe.penetration_tolerance_mm, 0.5);

  const RecipeRegistration* femur = registration_of(recipe, "femur_r");
  ASSERT_NE(femur, nullptr);
  EXPECT_EQ(femur->method, "head_and_condyles");
  EXPECT_EQ(femur->meshes, (std::vector<std::string>{"femur_r.vtp"}));
  const RecipeRegistration* tibia = registration_of(recipe, "tibia_r");
  ASSERT_NE(tibia, nullptr);
  EXPECT_EQ(tibia->method, "surface");
  EXPECT_EQ(tibia->targets, (std::vector<std::string>{"tibia_r", "fibula_r"}));
  EXPECT_EQ(tibia->joint_anchor, "knee_r");
  ASSERT_NE(registration_of(recipe, "toes_r"), nullptr);
  EXPECT_EQ(registration_of(recipe, "toes_r")->follow, "calcn_r");

  const auto biceps = std::ranges::find(recipe.muscles, std::string("biceps_femoris_long_head_r"),
                                        &RecipeMuscle::name);
  ASSERT_NE(biceps, recipe.muscles.end());
  EXPECT_TRUE(biceps->mirror);
  EXPECT_EQ(biceps->architecture, FibreArchitecture::kPennate);
  const auto gmax =
      std::ranges::find(recipe.muscles, std::string("gluteus_maximus_r"), &RecipeMuscle::name);
  ASSERT_NE(gmax, recipe.muscles.end());
  EXPECT_EQ(gmax->action_lines.size(), 3U);
  // One subject: every bone is a surface of hers, none an OpenSim mesh.
  for (const RecipeBone& bone : recipe.bones) {
    EXPECT_FALSE(bone.file.empty()) << bone.name;
    EXPECT_TRUE(bone.opensim_meshes.empty()) << bone.name;
  }
  EXPECT_EQ(recipe.bones.front().file, "vhf/registered/VHF_Right_Bone_Pelvis_registered.stl");
  const auto popliteus =
      std::ranges::find(recipe.muscles, std::string("popliteus_r"), &RecipeMuscle::name);
  ASSERT_NE(popliteus, recipe.muscles.end());
  EXPECT_EQ(popliteus->surface_line, (std::vector<std::string>{"femur_r", "tibia_r"}));
  EXPECT_TRUE(popliteus->action_lines.empty());
  // Wrap surfaces fitted to her bones replace gait2392's conditional points
  // of the gastrocnemii, semimembranosus, rectus femoris and iliopsoas.
  ASSERT_EQ(recipe.wrap_surfaces.size(), 3U);
  const RecipeWrapSurface& condyles = recipe.wrap_surfaces.front();
  EXPECT_EQ(condyles.shape, WrapShape::kCylinder);
  EXPECT_EQ(condyles.axis_of_joint, "knee_r");
  EXPECT_EQ(condyles.side, "posterior");
  EXPECT_EQ(condyles.replaces.size(), condyles.lines.size());
  // Her cartilages (hip, knee, patella, ankle) and four knee ligaments.
  ASSERT_EQ(recipe.structures.size(), 12U);
  EXPECT_EQ(std::ranges::count(recipe.structures, StructureKind::kLigament, &RecipeStructure::kind),
            4);
  for (const RecipeStructure& structure : recipe.structures) {
    EXPECT_EQ(structure.bones.size(), structure.kind == StructureKind::kLigament ? 2U : 1U)
        << structure.name;
  }
}

TEST(AtlasRecipeTest, SmallRecipeReads) {
  EXPECT_EQ(rejection(kRecipe), "");
  const test::ScratchDir dir("atlas_recipe");
  const AtlasRecipe recipe = read_atlas_recipe(test::write_file(dir / "r.yaml", kRecipe));
  EXPECT_EQ(recipe.bones.size(), 3U);
  EXPECT_EQ(recipe.registrations.size(), 3U);
  EXPECT_EQ(recipe.muscles.front().architecture, FibreArchitecture::kFanned);
  EXPECT_EQ(recipe.landmarks[1].joint, "knee_r");
  EXPECT_TRUE(recipe.registrations.front().anisotropic);  // the default
  EXPECT_DOUBLE_EQ(recipe.attachment_radius_mm, 30.0);    // the default
}

TEST(AtlasRecipeTest, UnknownFieldIsNamedWithItsLine) {
  const std::string message =
      rejection(edited("file: sacrum.stl, region", "file: sacrum.stl, colour: red, region"));
  EXPECT_THAT(message, HasSubstr("line 9:"));
  EXPECT_THAT(message, HasSubstr("bones[0].colour: unknown field (expected one of: body, file"));
  EXPECT_THAT(rejection(edited("name: tiny", "name: tiny\nauthor: me")),
              HasSubstr("line 3:1: (top).author: unknown field"));
  EXPECT_THAT(rejection(edited("joint_anchor: knee_r", "joint_anchor: knee_r, wobble: 2")),
              HasSubstr("registration.tibia_r.wobble: unknown field"));
}

TEST(AtlasRecipeTest, UnknownRegistrationMethodIsRejected) {
  // The message lists the known methods (the list grows; its ends are fixed).
  const std::string message = rejection(edited("{method: surface", "{method: telepathy"));
  EXPECT_THAT(message, HasSubstr("line 15:21: registration.tibia_r.method: unknown method "
                                 "'telepathy' (expected surface, "));
  EXPECT_THAT(message, HasSubstr("hip_and_sacrum or follow)"));
}

TEST(AtlasRecipeTest, RegistrationWithoutMeshesIsRejected) {
  EXPECT_THAT(rejection(edited("meshes: [tibia_r.vtp], ", "")),
              HasSubstr("registration.tibia_r.meshes: is required by method surface (the "
                        "OpenSim meshes to fit)"));
  // A follower needs none, but must name whom it follows.
  EXPECT_EQ(rejection(edited("{method: surface, meshes: [tibia_r.vtp], targets: [tibia_r], "
                             "joint_anchor: knee_r}",
                             "{method: follow, follow: femur_r}")),
            "");
  EXPECT_THAT(rejection(edited("{method: surface, meshes: [tibia_r.vtp], targets: [tibia_r], "
                               "joint_anchor: knee_r}",
                               "{method: follow}")),
              HasSubstr("registration.tibia_r.follow: is required by method follow"));
  EXPECT_THAT(rejection(edited("head: head.stl, ", "")),
              HasSubstr("registration.femur_r.head: is required by method head_and_condyles"));
}

TEST(AtlasRecipeTest, UnknownTargetBoneIsRejected) {
  EXPECT_THAT(rejection(edited("targets: [tibia_r]", "targets: [tibia_x]")),
              HasSubstr("registration.tibia_r.targets: unknown bone 'tibia_x'"));
  EXPECT_THAT(rejection(edited("sacrum: sacrum}", "sacrum: os_sacrum}")),
              HasSubstr("registration.pelvis.sacrum: unknown bone"));
  EXPECT_THAT(rejection(edited("midline: sacrum", "midline: spine")),
              HasSubstr("line 4:10: midline: unknown bone 'spine'"));
  EXPECT_THAT(rejection(edited("bone: femur_r, method: joint_centre",
                               "bone: femoral, method: joint_centre")),
              HasSubstr("landmarks[1].bone: unknown bone 'femoral'"));
}

TEST(AtlasRecipeTest, ASurfaceLineNeedsTwoKnownBonesAndNoOpenSimPath) {
  EXPECT_EQ(rejection(edited("action_lines: [glut_max1_r]", "surface_line: [sacrum, femur_r]")),
            "");
  EXPECT_THAT(rejection(edited("action_lines: [glut_max1_r]", "surface_line: [sacrum]")),
              HasSubstr("muscles[0].surface_line: expects two bones"));
  EXPECT_THAT(rejection(edited("action_lines: [glut_max1_r]", "surface_line: [sacrum, femr]")),
              HasSubstr("muscles[0].surface_line: unknown bone 'femr'"));
  EXPECT_THAT(rejection(edited("action_lines: [glut_max1_r]",
                               "action_lines: [glut_max1_r], surface_line: [sacrum, femur_r]")),
              HasSubstr("either action_lines (OpenSim paths) or a surface_line"));
}

TEST(AtlasRecipeTest, AWrapSurfaceNamesItsBoneShapeCentreAndKnownLines) {
  const std::string surface =
      "wrap_surfaces:\n  - {name: s, bone: femur_r, shape: cylinder, around_joint: knee_r,\n"
      "     side: posterior, axis_of_joint: knee_r, lines: [glut_max1_r], replaces: [P2]}\n";
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = std::string(kRecipe) + surface;
    // Edits apply to the wrap surface (after the recipe's own text).
    if (!from.empty()) text.replace(text.find(from, std::string(kRecipe).size()), from.size(), to);
    return rejection(text);
  };
  EXPECT_EQ(with("", ""), "");
  EXPECT_THAT(with("bone: femur_r, shape", "bone: femr, shape"),
              HasSubstr("wrap_surfaces[0].bone: unknown bone 'femr'"));
  EXPECT_THAT(with("cylinder", "torus"), HasSubstr("unknown shape 'torus'"));
  EXPECT_THAT(with("around_joint: knee_r", "around_point: x-P1, around_joint: knee_r"),
              HasSubstr("by around_joint or around_point (one)"));
  EXPECT_THAT(with("around_joint: knee_r,", ""), HasSubstr("by around_joint or around_point"));
  EXPECT_THAT(with("posterior", "behind"), HasSubstr("unknown side 'behind'"));
  EXPECT_THAT(with("cylinder", "sphere"), HasSubstr("axis_of_joint: is for cylinders only"));
  EXPECT_THAT(with("lines: [glut_max1_r]", "lines: [glut_max9_r]"),
              HasSubstr("'glut_max9_r' is not an action line of any muscle"));
  EXPECT_THAT(with("lines: [glut_max1_r]", "lines: []"), HasSubstr("names at least one line"));
  EXPECT_THAT(with("replaces", "offset_mm: 80, replaces"),
              HasSubstr("wrap_surfaces[0].offset_mm: is 80, outside [0, 50]"));
}

TEST(AtlasRecipeTest, AStructureNamesItsKindFileAndBones) {
  const std::string structure =
      "structures:\n  - {name: acl, kind: ligament, file: acl.stl, bones: [femur_r, tibia_r],\n"
      "     region: pelvis, tags: [ligament]}\n";
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = std::string(kRecipe) + structure;
    if (!from.empty()) text.replace(text.find(from, std::string(kRecipe).size()), from.size(), to);
    return rejection(text);
  };
  EXPECT_EQ(with("", ""), "");
  EXPECT_THAT(with("kind: ligament", "kind: tendon"),
              HasSubstr("structures[0].kind: unknown kind 'tendon' (expected cartilage or "
                        "ligament)"));
  EXPECT_THAT(with("bones: [femur_r, tibia_r]", "bones: [femur_r]"),
              HasSubstr("a ligament names the two different bones it joins: [from, to]"));
  EXPECT_THAT(with("bones: [femur_r, tibia_r]", "bones: [femur_r, femur_r]"),
              HasSubstr("two different bones"));
  EXPECT_THAT(with("kind: ligament", "kind: cartilage"),
              HasSubstr("a cartilage names the one bone it covers: [bone]"));
  EXPECT_THAT(with("bones: [femur_r, tibia_r]", "bones: [femur_r, tibia]"),
              HasSubstr("structures[0].bones: unknown bone 'tibia'"));
  EXPECT_THAT(with("name: acl", "name: femur_r"),
              HasSubstr("'femur_r' is already the name of a bone or muscle"));
  EXPECT_THAT(with("file: acl.stl, ", ""), HasSubstr("structures[0].file: is required"));
  EXPECT_THAT(with("region: pelvis", "region: knee"), HasSubstr("unknown region 'knee'"));
  EXPECT_THAT(with("region: pelvis", "muscle_ends_clear_mm: 3, region: pelvis"),
              HasSubstr("structures[0].muscle_ends_clear_mm: is for cartilages only"));
  EXPECT_THAT(with("kind: ligament, file: acl.stl, bones: [femur_r, tibia_r]",
                   "kind: cartilage, file: acl.stl, bones: [femur_r], muscle_ends_clear_mm: 30"),
              HasSubstr("muscle_ends_clear_mm: is 30, outside [0, 20]"));
}

TEST(AtlasRecipeTest, DuplicateNamesAreRejected) {
  EXPECT_THAT(rejection(edited("{name: tibia_r, body", "{name: femur_r, body")),
              HasSubstr("line 11:5: bones[2].name: duplicate name 'femur_r'"));
  EXPECT_THAT(rejection(edited("name: knee_r, bone", "name: head_r, bone")),
              HasSubstr("landmarks[1].name: duplicate name 'head_r'"));
}

TEST(AtlasRecipeTest, LodFacesMustDecrease) {
  EXPECT_THAT(rejection(edited("[4000, 1000]", "[1000, 4000]")),
              HasSubstr("lod_faces[1]: levels must get coarser (decreasing face counts)"));
  EXPECT_THAT(rejection(edited("[4000, 1000]", "[1000, 1000]")),
              HasSubstr("lod_faces[1]: levels must get coarser"));
  EXPECT_THAT(rejection(edited("[4000, 1000]", "[4000, 10.5]")),
              HasSubstr("lod_faces[1]: expects a whole number of faces in [100, 1e7]"));
}

TEST(AtlasRecipeTest, UnknownArchitectureIsRejected) {
  EXPECT_THAT(rejection(edited("architecture: fanned", "architecture: spiral")),
              HasSubstr("line 17:"));
  EXPECT_THAT(rejection(edited("architecture: fanned", "architecture: spiral")),
              HasSubstr("muscles[0].architecture: unknown architecture 'spiral' (expected "
                        "parallel, pennate, fanned or curved)"));
}

TEST(AtlasRecipeTest, LandmarkMethodsNeedTheirInputs) {
  EXPECT_THAT(rejection(edited("sphere_centre, file: head.stl}", "sphere_centre}")),
              HasSubstr("landmarks[0].file: is required by sphere_centre"));
  EXPECT_THAT(rejection(edited("joint_centre, joint: knee_r}", "joint_centre}")),
              HasSubstr("landmarks[1].joint: is required by joint_centre"));
  EXPECT_THAT(rejection(edited("joint_centre, joint: knee_r}", "marker_on_bone}")),
              HasSubstr("landmarks[1].marker: is required by marker_on_bone"));
  EXPECT_THAT(rejection(edited("joint_centre, joint: knee_r}", "guess}")),
              HasSubstr("landmarks[1].method: unknown method 'guess'"));
}

TEST(AtlasRecipeTest, WrongFormatVersionIsRejected) {
  EXPECT_THAT(rejection(edited("mmm_atlas_recipe: 1", "mmm_atlas_recipe: 2")),
              HasSubstr("line 1:19: mmm_atlas_recipe: this mmm reads recipe format 1 (write "
                        "`mmm_atlas_recipe: 1` at the top)"));
  EXPECT_THAT(rejection(edited("mmm_atlas_recipe: 1\n", "")),
              HasSubstr("mmm_atlas_recipe: this mmm reads recipe format 1"));
}

TEST(AtlasRecipeTest, MalformedYamlGivesTheLine) {
  // An unclosed flow mapping on line 7: the parser notices at the next
  // block entry, line 9, which is the line it reports.
  const std::string message =
      rejection(edited("{name: pelvis, tags: [region]}", "{name: pelvis, tags: [region]"));
  EXPECT_THAT(message, HasSubstr("line 9: malformed YAML: "));
  // A second value on one key: noticed on its own line, 4.
  EXPECT_THAT(rejection(edited("midline: sacrum", "midline: sacrum: coccyx")),
              HasSubstr("line 4: malformed YAML"));
  EXPECT_THAT(rejection("- just\n- a list\n"), HasSubstr("(top): expects a mapping"));
}

TEST(AtlasRecipeTest, BonesNeedOneSourceAndARegisteredBody) {
  EXPECT_THAT(rejection(edited("file: tibia.stl}", "file: tibia.stl, opensim_meshes: [t.vtp]}")),
              HasSubstr("bones[2]: give either `file` (a surface in the atlas frame) or "
                        "`opensim_meshes` (meshes of the OpenSim body), not both or none"));
  EXPECT_THAT(rejection(edited("file: tibia.stl}", "tags: [x]}")),
              HasSubstr("bones[2]: give either `file`"));
  EXPECT_THAT(rejection(edited("body: tibia_r", "body: talus_r")),
              HasSubstr("line 11:27: bones[2].body: body 'talus_r' has no entry under "
                        "registration:"));
  EXPECT_THAT(
      rejection(edited("region: pelvis}\n  - {name: femur_r", "region: hips}\n  - {name: femur_r")),
      HasSubstr("bones[0].region: unknown region 'hips' (declare it under regions:)"));
}

TEST(AtlasRecipeTest, OutOfRangeNumbersAndMissingFieldsAreRejected) {
  EXPECT_THAT(rejection(edited("lod_faces", "penetration_tolerance_mm: 9\nlod_faces")),
              HasSubstr("(top).penetration_tolerance_mm: is 9, outside [0, 5]"));
  EXPECT_THAT(rejection(edited("lod_faces", "attachment_radius_mm: wide\nlod_faces")),
              HasSubstr("(top).attachment_radius_mm: expects a finite number, got 'wide'"));
  EXPECT_THAT(rejection(edited("name: tiny\n", "")), HasSubstr("(top).name: is required"));
  EXPECT_THAT(rejection(edited(", geometry: Geometry", "")),
              HasSubstr("opensim.geometry: is required"));
  EXPECT_THAT(rejection(edited("{name: sacrum, body: pelvis, file: sacrum.stl, region: pelvis}",
                               "{name: sacrum, body: pelvis, file: sacrum.stl, mirror: maybe}")),
              HasSubstr("bones[0].mirror: expects true or false"));
}

TEST(AtlasRecipeTest, MissingFileIsAnIoError) {
  const test::ScratchDir dir("atlas_recipe");
  try {
    (void)read_atlas_recipe(dir / "absent.yaml");
    FAIL() << "expected an IoError";
  } catch (const IoError& error) {
    EXPECT_THAT(std::string(error.what()), HasSubstr("cannot open the recipe"));
  }
}

}  // namespace
}  // namespace mmm::atlas
