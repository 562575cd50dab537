// Outline fitting of a whole (toy) atlas: a patient whose femur is wider and
// shifted, rendered into a calibrated pair; the fitted femur comes close to
// it, the tibia fitted after it with the femur taken out stays right, the
// bones not asked for are left alone, and everything that follows the
// bones (carry_atlas) stays where an identity placement puts it.

#include <gtest/gtest.h>

#include <memory>

#include "core/image/drr.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/surface_distance.h"
#include "core/outlines/atlas_outline_fit.h"
#include "core/scaling/atlas_scaling.h"
#include "tests/support/test_data.h"
#include "tests/support/toy_leg_atlas.h"

namespace mmm::outlines {
namespace {

using Eigen::Vector3d;

// The toy leg's femur, 12 % wider across and moved 1.5 mm right and 1 mm
// back: what no landmark of the station would show.
mesh::IndexedMesh patient_femur(const mesh::IndexedMesh& femur) {
  mesh::IndexedMesh out = femur;
  const Vector3d centre = femur.V.colwise().mean().transpose();
  for (Eigen::Index i = 0; i < out.V.rows(); ++i) {
    Vector3d p = out.V.row(i).transpose() - centre;
    p.x() *= 1.12;
    p.y() *= 1.12;
    out.V.row(i) = (centre + p + Vector3d(1.5, -1.0, 0.0)).transpose();
  }
  return out;
}

image::RadiographPair render_pair(const std::map<std::string, mesh::IndexedMesh>& bones,
                                  const std::filesystem::path& dir) {
  Eigen::AlignedBox3d box;
  for (const auto& [name, surface] : bones) box.extend(mesh::bounding_box(surface));
  image::BiplanarOptions geometry;
  geometry.isocentre_mm = box.center();
  geometry.field_width_mm = std::max(box.sizes().x(), box.sizes().y()) + 40;
  geometry.field_height_mm = box.sizes().z() + 40;
  geometry.detector_pixel_pitch_mm = 0.8;
  const auto views = image::make_biplanar_views(geometry);
  std::vector<std::unique_ptr<mesh::AabbTree>> trees;
  std::vector<image::AttenuatingMesh> meshes;
  for (const auto& [name, surface] : bones) {
    trees.push_back(std::make_unique<mesh::AabbTree>(surface));
    meshes.push_back({trees.back().get(), image::kBoneMuPerMm});
  }
  std::vector<image::RadiographFile> files;
  image::RadiographOptions detector;
  detector.seed = 3;
  for (const image::RadiographView& view : views) {
    image::write_png(image::to_radiograph(image::render_drr(view, meshes), detector),
                     dir / (view.name + ".png"));
    files.push_back({view, view.name + ".png"});
  }
  image::write_view_sidecar(dir / "views.json", files);
  return image::load_radiograph_pair(dir / "views.json");
}

TEST(AtlasOutlineFitTest, AWiderFemurIsFittedAndTheBonesNotAskedForStay) {
  const test::ToyLeg leg = test::toy_leg();
  std::map<std::string, mesh::IndexedMesh> truth;
  for (const atlas::Bone& bone : leg.atlas.bones)
    truth[bone.name] = leg.meshes.at(bone.name).at("full");
  truth["femur_r"] = patient_femur(truth["femur_r"]);
  const test::ScratchDir dir("outline_fit");
  const image::RadiographPair pair = render_pair(truth, dir.path());

  AtlasOutlineFitOptions options;
  options.bones = {"femur_r", "tibia_r"};
  options.rounds = {{"*"}, {"tibia_r"}};
  const AtlasOutlineFit fit = fit_atlas_outlines(leg.atlas, leg.meshes, {}, pair, {}, options);
  ASSERT_EQ(fit.bones.size(), 2U);
  EXPECT_NE(std::ranges::find(fit.not_fitted, "pelvis"), fit.not_fitted.end());
  const mesh::IndexedMesh& start = leg.meshes.at("femur_r").at("full");
  const double before = mesh::surface_distance(start, truth.at("femur_r")).mean_mm;
  const mesh::IndexedMesh fitted{fit.bones[0].vertices, start.F};
  const double after = mesh::surface_distance(fitted, truth.at("femur_r")).mean_mm;
  EXPECT_GT(before, 1.5);
  EXPECT_LT(after, 0.25 * before) << before << " -> " << after;
  // The tibia was right: it stays within a fraction of a pixel.
  const mesh::IndexedMesh tibia{fit.bones[1].vertices, leg.meshes.at("tibia_r").at("full").F};
  EXPECT_LT(mesh::surface_distance(tibia, truth.at("tibia_r")).mean_mm, 0.3);
  for (const ViewFit& view : fit.bones[0].views) {
    EXPECT_LT(view.mean_mm, view.start_mean_mm) << view.view;
  }
  // The tibia is fitted after the femur, with the fitted femur taken out
  // (they overlap at the knee in both views); the femur on the images as they
  // are.
  EXPECT_TRUE(fit.bones[0].neighbours_removed_px.empty());
  ASSERT_EQ(fit.bones[1].neighbours_removed_px.size(), 2U);
  for (const int pixels : fit.bones[1].neighbours_removed_px) EXPECT_GT(pixels, 100);
  // Without the thickness term there is no gain to take a bone out with:
  // every bone is fitted once.
  options.fit.thickness.weight = 0.0;
  const AtlasOutlineFit once = fit_atlas_outlines(leg.atlas, leg.meshes, {}, pair, {}, options);
  for (const BoneOutlineFit& bone : once.bones) {
    EXPECT_TRUE(bone.neighbours_removed_px.empty()) << bone.bone;
  }
}

TEST(AtlasOutlineFitTest, UnknownBonesAndViewsOfCorrectionsAreRejected) {
  const test::ToyLeg leg = test::toy_leg();
  std::map<std::string, mesh::IndexedMesh> bones;
  for (const atlas::Bone& bone : leg.atlas.bones)
    bones[bone.name] = leg.meshes.at(bone.name).at("lod1");
  const test::ScratchDir dir("outline_fit");
  const image::RadiographPair pair = render_pair(bones, dir.path());
  AtlasOutlineFitOptions options;
  options.bones = {"femur_r", "fibula_r"};
  EXPECT_THROW(fit_atlas_outlines(leg.atlas, leg.meshes, {}, pair, {}, options), InvalidInputError);
  options.bones = {"femur_r"};
  const std::vector<OutlineCorrection> wrong_view = {{"femur_r", "oblique", {{10, 10}}}};
  EXPECT_THROW(fit_atlas_outlines(leg.atlas, leg.meshes, {}, pair, wrong_view, options),
               InvalidInputError);
  const std::vector<OutlineCorrection> unfitted = {{"tibia_r", "frontal", {{10, 10}}}};
  EXPECT_THROW(fit_atlas_outlines(leg.atlas, leg.meshes, {}, pair, unfitted, options),
               InvalidInputError);
}

TEST(CarryAtlasTest, AnIdentityPlacementLeavesEveryBoneAndStructureWhereItWas) {
  const test::ToyLeg leg = test::toy_leg();
  const auto prepared = scaling::prepare_atlas(leg.atlas, leg.meshes);
  scaling::BonePlacement placement;
  for (const atlas::Bone& bone : leg.atlas.bones) {
    placement.vertices[bone.name] = leg.meshes.at(bone.name).at("full").V;
    placement.affine[bone.name] = Eigen::Affine3d::Identity();
  }
  scaling::ScaledAtlas carried;
  scaling::carry_atlas(*prepared, placement, {}, carried);
  for (const atlas::Bone& bone : leg.atlas.bones) {
    for (const auto& [level, surface] : leg.meshes.at(bone.name)) {
      EXPECT_LT((carried.meshes.at(bone.name).at(level).V - surface.V).cwiseAbs().maxCoeff(), 1e-6)
          << bone.name << " " << level;
    }
  }
  for (std::size_t i = 0; i < leg.atlas.landmarks.size(); ++i) {
    EXPECT_LT((carried.atlas.landmarks[i].position - leg.atlas.landmarks[i].position).norm(), 1e-6);
  }
  EXPECT_NEAR(carried.muscles[0].solution.volume_ratio, 1.0, 1e-3);
  placement.vertices.erase("femur_r");
  EXPECT_THROW(scaling::carry_atlas(*prepared, placement, {}, carried), InvalidInputError);
}

}  // namespace
}  // namespace mmm::outlines
