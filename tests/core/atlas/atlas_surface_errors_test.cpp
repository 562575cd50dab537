#include "core/atlas/atlas_surface_errors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/atlas/atlas_meshes.h"
#include "core/errors.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::atlas {
namespace {

const ElementSurfaceError& find(const std::vector<ElementSurfaceError>& errors,
                                const std::string& element) {
  const auto it = std::find_if(errors.begin(), errors.end(),
                               [&](const ElementSurfaceError& e) { return e.element == element; });
  EXPECT_NE(it, errors.end()) << element;
  return *it;
}

TEST(AtlasSurfaceErrorsTest, AnAtlasAgainstItselfIsExactAndAMovedBoneIsBoundedByTheMove) {
  const test::ScratchDir scratch("surface_errors");
  test::write_toy_leg(scratch / "truth");
  test::ToyLeg moved = test::toy_leg();
  constexpr double kShiftMm = 3.0;
  for (auto& [level, mesh] : moved.meshes.at("femur_r")) mesh.V.col(0).array() += kShiftMm;
  write_atlas_with_meshes(moved.atlas, moved.meshes, scratch / "estimate");

  const std::vector<ElementSurfaceError> same =
      atlas_surface_errors(scratch / "truth", scratch / "truth");
  ASSERT_EQ(same.size(), moved.atlas.bones.size() + moved.atlas.muscles.size());
  EXPECT_EQ(same.front().kind, "bone");
  EXPECT_EQ(same.back().kind, "muscle");
  for (const ElementSurfaceError& e : same) {
    EXPECT_EQ(e.distance.max_mm, 0.0) << e.element;
    EXPECT_GT(e.distance.samples, 0) << e.element;
  }

  const std::vector<ElementSurfaceError> errors =
      atlas_surface_errors(scratch / "estimate", scratch / "truth", "full", 1);
  const mesh::SurfaceDistance femur = find(errors, "femur_r").distance;
  // A translation moves every vertex by the shift, so no vertex is further
  // than that from the other surface; the long sides slide along
  // themselves, so the mean is well below it.
  EXPECT_LE(femur.max_mm, kShiftMm + 1e-9);
  EXPECT_GT(femur.max_mm, 0.5 * kShiftMm);
  EXPECT_GT(femur.mean_mm, 0.0);
  EXPECT_LT(femur.mean_mm, femur.max_mm);
  EXPECT_LE(femur.p95_mm, femur.max_mm);
  EXPECT_EQ(find(errors, "tibia_r").distance.max_mm, 0.0);
  EXPECT_EQ(find(errors, "pelvis").distance.max_mm, 0.0);
}

TEST(AtlasSurfaceErrorsTest, AnElementMissingFromTheTruthIsNamed) {
  const test::ScratchDir scratch("surface_errors_missing");
  test::write_toy_leg(scratch / "estimate");
  test::ToyLeg truth = test::toy_leg();
  const std::string muscle = truth.atlas.muscles.front().name;
  truth.meshes.erase(muscle);
  truth.atlas.muscles.clear();
  write_atlas_with_meshes(truth.atlas, truth.meshes, scratch / "truth");
  try {
    atlas_surface_errors(scratch / "estimate", scratch / "truth");
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("no muscle '" + muscle + "'"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(atlas_surface_errors(scratch / "estimate", scratch / "nowhere"), IoError);
}

}  // namespace
}  // namespace mmm::atlas
