#include "nodes/fit_bone_outlines.h"

#include <chrono>
#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include "core/atlas/atlas_io.h"
#include "core/atlas/atlas_meshes.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/image/outline_corrections.h"
#include "core/image/outline_overlay.h"
#include "core/image/png.h"
#include "core/image/radiograph_pair.h"
#include "core/landmarks/landmark_set.h"
#include "core/outlines/atlas_outline_fit.h"
#include "core/scaling/atlas_scaling.h"
#include "nodes/name_list.h"

namespace mmm::nodes {
namespace {

std::string bone_list(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// Rounds as "BONE, BONE; BONE, ..." (rounds separated by semicolons).
std::string round_list(const std::vector<std::vector<std::string>>& rounds) {
  std::string text;
  for (const std::vector<std::string>& round : rounds) {
    text += (text.empty() ? "" : "; ") + bone_list(round);
  }
  return text;
}

std::vector<std::vector<std::string>> rounds_from(const std::string& text) {
  std::vector<std::vector<std::string>> rounds;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ';')) {
    std::vector<std::string> round = split_names(item);
    if (round.empty()) {
      throw InvalidInputError("fit_bone_outlines: parameter 'rounds': an empty round in '" + text +
                              "'; hint: rounds are separated by ';', bones by ',', e.g. "
                              "\"*, tibia_r; fibula_r, pelvis\"");
    }
    rounds.push_back(std::move(round));
  }
  return rounds;
}

std::string factor_list(const std::map<std::string, double>& factors) {
  std::string text;
  for (const auto& [bone, factor] : factors) {
    std::ostringstream item;
    item << bone << '=' << factor;
    text += (text.empty() ? "" : ", ") + item.str();
  }
  return text;
}

// "bone=factor, ..." -> map (the bones are checked against the atlas by the fit).
std::map<std::string, double> membrane_factors(const std::string& text) {
  std::map<std::string, double> factors;
  for (const std::string& item : split_names(text)) {
    const auto equals = item.find('=');
    double factor = std::nan("");
    if (equals != std::string::npos && equals > 0) {
      try {
        std::size_t used = 0;
        const std::string number = item.substr(equals + 1);
        factor = std::stod(number, &used);
        if (used != number.size()) factor = std::nan("");
      } catch (const std::exception&) {
        factor = std::nan("");
      }
    }
    if (!(factor > 0 && factor <= 1e3)) {
      throw InvalidInputError("fit_bone_outlines: parameter 'membrane_factors': '" + item +
                              "' is not BONE=FACTOR with a factor in (0, 1000]; hint: e.g. "
                              "pelvis=3, sacrum=3");
    }
    factors[item.substr(0, equals)] = factor;
  }
  return factors;
}

outlines::AtlasOutlineFitOptions options_from(const workflow::NodeContext& context) {
  outlines::AtlasOutlineFitOptions options;
  options.bones = split_names(context.text("bones"));
  options.membrane_factor = membrane_factors(context.text("membrane_factors"));
  options.work_level = context.text("work_level");
  options.fit.node_spacing_mm = context.number("node_spacing_mm");
  options.fit.smoothness_weight = context.number("smoothness_weight");
  options.fit.bending_weight = context.number("bending_weight");
  options.fit.robust_mm = context.number("robust_mm");
  options.fit.thickness.weight = context.number("thickness_weight");
  options.tissue_free_bones = split_names(context.text("tissue_free_bones"));
  options.rounds = rounds_from(context.text("rounds"));
  options.threads = static_cast<int>(context.integer("threads"));
  return options;
}

nlohmann::json fit_report(const outlines::AtlasOutlineFit& fit) {
  nlohmann::json bones = nlohmann::json::array();
  for (const outlines::BoneOutlineFit& bone : fit.bones) {
    nlohmann::json views = nlohmann::json::array();
    for (std::size_t v = 0; v < bone.views.size(); ++v) {
      const outlines::ViewFit& view = bone.views[v];
      views.push_back({{"view", view.view},
                       {"contour_points", view.contour_points},
                       {"matched", view.matched},
                       {"start_mean_mm", view.start_mean_mm},
                       {"mean_mm", view.mean_mm},
                       {"p95_mm", view.p95_mm},
                       {"thickness_samples", view.thickness_samples},
                       {"thickness_mean_mm", view.thickness_mean_mm},
                       {"thickness_gain", view.thickness_gain},
                       {"neighbours_removed_px",
                        v < bone.neighbours_removed_px.size() ? bone.neighbours_removed_px[v] : 0},
                       {"corrections", view.corrections},
                       {"correction_mean_mm", view.correction_mean_mm}});
    }
    nlohmann::json entry = {{"bone", bone.bone},
                            {"converged", bone.converged},
                            {"last_change_mm", bone.last_change_mm},
                            {"last_change_p95_mm", bone.last_change_p95_mm},
                            {"iterations", bone.iterations},
                            {"nodes", bone.nodes},
                            {"moved_mean_mm", bone.moved_mean_mm},
                            {"moved_max_mm", bone.moved_max_mm},
                            {"held_by_prior", bone.held_by_prior},
                            {"seconds", bone.seconds},
                            {"views", views},
                            {"pin_residual_mm", bone.pin_residual_mm}};
    // Where the images do not decide the shape, the scaled atlas's holds.
    if (bone.held_by_prior > 0.25) {
      entry["note"] = "the images determine little of this bone (" +
                      std::to_string(std::lround(100 * bone.held_by_prior)) +
                      " % of its surface held by the prior: superimposed or seen edge-on)";
    }
    bones.push_back(entry);
  }
  // The soft tissue's law on each view, when the thickness term modelled it.
  nlohmann::json soft = nlohmann::json::array();
  for (const outlines::SoftTissueLaw& law : fit.soft_tissue) {
    soft.push_back({{"view", law.view},
                    {"used", law.used},
                    {"offset", law.offset},
                    {"tissue_per_mm", law.tissue_per_mm},
                    {"muscle_per_mm", law.muscle_per_mm},
                    {"pixels", law.samples},
                    {"residual_rms", law.residual_rms},
                    {"outline_rows", law.rows_matched},
                    {"limb_width_ratio", law.median_width_ratio}});
  }
  return {{"format", "mmm-outline-fit"},
          {"version", 1},
          {"bones", bones},
          {"soft_tissue", soft},
          {"not_fitted", fit.not_fitted},
          {"images_seconds", fit.images_seconds},
          {"fit_seconds", fit.fit_seconds}};
}

image::RgbImage8 overlay_picture(const atlas::Atlas& atlas, const atlas::AtlasMeshes& before,
                                 const atlas::AtlasMeshes& after,
                                 const outlines::AtlasOutlineFit& fit,
                                 const image::RadiographPair& pair) {
  std::vector<image::OutlineItem> items;
  for (const outlines::BoneOutlineFit& bone : fit.bones) {
    const atlas::Bone* b = atlas.find_bone(bone.bone);
    const std::string level = b->meshes.size() > 1 ? b->meshes[1].level : "full";
    items.push_back({bone.bone + " (scaled)", &before.at(bone.bone).at(level), {255, 70, 70}});
    items.push_back({bone.bone + " (fitted)", &after.at(bone.bone).at(level), {70, 255, 90}});
  }
  image::OverlayOptions options;
  options.legend = false;
  return image::outline_overlay_pair(pair, items, options);
}

}  // namespace

workflow::NodeSpec FitBoneOutlines::spec() {
  using workflow::port::Atlas;
  using workflow::port::File;
  using workflow::port::LandmarkSet;
  using workflow::port::RadiographPair;
  using workflow::port::Report;
  const outlines::AtlasOutlineFitOptions d;
  return workflow::NodeSpec{
      "fit_bone_outlines", 1,
      "Fit the scaled bones to their outlines on both radiographs (silhouette-based 2D-3D "
      "fit, the scaled shape as prior, the operator's landmarks held); muscles and every "
      "derived element follow the bones"}
      .resources(2, 3072)
      .input<Atlas>("atlas", "The scaled atlas (scale_atlas)")
      .input<RadiographPair>("radiographs", "The patient's calibrated radiograph pair")
      .optional_input<LandmarkSet>("landmarks", "The operator's landmarks, held in place")
      .optional_input<workflow::port::OutlineCorrections>(
          "corrections",
          "An operator's review of this atlas's outlines (outline_review): accepted, the atlas "
          "passes through unchanged; corrected, the fit runs again with the operator's points")
      .param<std::string>("bones", bone_list(d.bones),
                          "Bones fitted (comma-separated); the others keep the scaled shape")
      .param<std::string>("work_level", d.work_level,
                          "Mesh level whose contours are matched (the full level is moved)")
      .param<double>("node_spacing_mm", d.fit.node_spacing_mm,
                     "Spacing of the deformation field's nodes", {.min = 2, .max = 50}, "mm")
      .param<double>("smoothness_weight", d.fit.smoothness_weight,
                     "Weight keeping neighbouring nodes' displacements alike (first stage; "
                     "the finer stages use a fifth and a tenth of it)",
                     {.min = 1e-6, .max = 1e6})
      .param<std::string>("membrane_factors", factor_list(d.membrane_factor),
                          "Per bone, a factor on smoothness_weight (BONE=FACTOR, comma-separated): "
                          "the hip bones and sacrum, whose outlines cross many other edges, are "
                          "held stiffer")
      .param<double>("bending_weight", d.fit.bending_weight,
                     "Weight keeping each node's displacement that of its neighbours' linear "
                     "field (local widening is free, dents are not)",
                     {.min = 0, .max = 1e6})
      .param<double>("robust_mm", d.fit.robust_mm,
                     "Contour residuals beyond this count linearly (Huber)",
                     {.min = 0.05, .max = 20}, "mm")
      .param<double>("thickness_weight", d.fit.thickness.weight,
                     "Weight per sample ray of the bone's brightness inside its outline against "
                     "the ray's length through the surface (0: outlines only; the rays together "
                     "weigh at most twice the outline; off for the hip bones and sacrum). The "
                     "soft tissue under each bone is predicted from the atlas's muscles and the "
                     "limb's outline on the images",
                     {.min = 0, .max = 100})
      .param<std::string>("tissue_free_bones", bone_list(d.tissue_free_bones),
                          "Bones whose outlines are sought with the predicted soft tissue taken "
                          "out of the radiographs (comma-separated; empty: none)")
      .param<std::string>(
          "rounds", round_list(d.rounds),
          "The fit's rounds, in order (';' between rounds, ',' between bones; '*': every bone "
          "no round names; bones named nowhere come first). A later round fits its bones again "
          "on radiographs with the other bones' latest fits taken out (needs the thickness "
          "term); bones not fitted are ignored")
      .param<std::int64_t>("threads", d.threads, "Worker threads", {.min = 1, .max = 64})
      .output<Atlas>("atlas", "The patient's atlas with the bones fitted to the radiographs")
      .output<Report>("report", "Per bone and view: contour residuals, movement, convergence")
      .output<File>("overlay", "PNG: scaled (red) and fitted (green) outlines on the radiographs");
}

void FitBoneOutlines::run(workflow::NodeContext& context) {
  outlines::AtlasOutlineFitOptions options = options_from(context);
  const auto started = std::chrono::steady_clock::now();
  context.progress(0, 5, "reading the scaled atlas");
  const std::filesystem::path in = context.scratch_dir() / "atlas_in";
  unpack_directory(context.input_bytes("atlas"), in, "input 'atlas'");
  atlas::Atlas scaled = atlas::read_atlas(in);
  atlas::AtlasMeshes meshes = atlas::read_atlas_meshes(scaled, in, options.threads);
  const image::RadiographPair pair = image::radiograph_pair_from_json_text(
      context.input_bytes("radiographs"), "input 'radiographs'");
  landmarks::LandmarkSet given;
  if (context.has_input("landmarks")) {
    given = landmarks::landmark_set_from_json_text(context.input_bytes("landmarks"),
                                                   "input 'landmarks'");
  }
  // An operator's review: accepted as it is, or points to fit to.
  std::vector<outlines::OutlineCorrection> corrections;
  if (context.has_input("corrections")) {
    const image::OutlineCorrections review =
        image::read_outline_corrections(context.input_bytes("corrections"), "input 'corrections'");
    if (review.decision == image::OutlineDecision::kAccept) {
      context.info("the operator accepted the outlines as they are: the atlas passes through");
      context.set_output("atlas", context.input_bytes("atlas"));
      const nlohmann::json report = {{"format", "mmm-outline-fit"},
                                     {"version", 1},
                                     {"decision", "accept"},
                                     {"bones", nlohmann::json::array()}};
      context.set_output("report", report.dump(2));
      const std::filesystem::path overlay = context.scratch_dir() / "overlay.png";
      const outlines::AtlasOutlineFit none;
      image::write_png(overlay_picture(scaled, meshes, meshes, none, pair), overlay);
      context.set_output_file("overlay", overlay);
      return;
    }
    for (const image::OutlineCorrection& c : review.corrections) {
      corrections.push_back({c.bone, c.view, c.points_px});
      // A bone the operator corrected is fitted, whether or not it was asked for.
      if (std::ranges::find(options.bones, c.bone) == options.bones.end()) {
        options.bones.push_back(c.bone);
      }
    }
  }
  // Bones of the list the atlas lacks (the default names the whole leg's)
  // are left out, and said so.
  std::vector<std::string> absent;
  std::erase_if(options.bones, [&](const std::string& bone) {
    const bool missing = scaled.find_bone(bone) == nullptr;
    if (missing) absent.push_back(bone);
    return missing;
  });
  if (!absent.empty()) {
    context.warn("bones not in the atlas, not fitted: " + bone_list(absent));
  }
  std::vector<std::string> unused;
  std::erase_if(options.membrane_factor, [&](const auto& entry) {
    const bool missing = scaled.find_bone(entry.first) == nullptr;
    if (missing) unused.push_back(entry.first);
    return missing;
  });
  if (!unused.empty()) {
    context.warn("membrane_factors names bones not in the atlas (ignored): " + bone_list(unused));
  }
  context.progress(1, 5, "fitting the outlines");
  const outlines::AtlasOutlineFit fit =
      outlines::fit_atlas_outlines(scaled, meshes, given, pair, corrections, options);
  const double pixel_mm = pair.calibrated_views().front().pixel_spacing_mm;
  for (const outlines::BoneOutlineFit& bone : fit.bones) {
    std::string line = bone.bone + ":";
    for (const outlines::ViewFit& view : bone.views) {
      line += " " + view.view + " " + std::to_string(view.start_mean_mm) + " -> " +
              std::to_string(view.mean_mm) + " mm;";
    }
    context.info(line + (bone.converged ? " converged" : " not converged"));
    // Edges searched again every iteration can keep a surface moving by a
    // fraction of a pixel; more than a pixel is worth a look.
    if (!bone.converged) {
      const std::string moving = bone.bone + ": the outline fit was still moving at its end (" +
                                 std::to_string(bone.last_change_p95_mm) +
                                 " mm in the last iteration, 95th percentile)";
      if (bone.last_change_p95_mm > pixel_mm) {
        context.warn(moving);
      } else {
        context.info(moving + ", less than a pixel");
      }
    }
  }
  context.progress(2, 5, "carrying muscles and derived elements");
  scaling::AtlasScalingOptions carry;
  carry.threads = options.threads;
  // The scaled atlas moves into the preparation; it is read from there on.
  const auto prepared = scaling::prepare_atlas(std::move(scaled), std::move(meshes), carry);
  const atlas::Atlas& start = prepared->atlas;
  const atlas::AtlasMeshes& start_meshes = prepared->meshes;
  scaling::BonePlacement placement;
  for (const atlas::Bone& bone : start.bones) {
    placement.vertices[bone.name] = start_meshes.at(bone.name).at("full").V;
    placement.affine[bone.name] = Eigen::Affine3d::Identity();
  }
  for (const outlines::BoneOutlineFit& bone : fit.bones) {
    placement.vertices[bone.bone] = bone.vertices;
    Eigen::Affine3d affine = Eigen::Affine3d::Identity();
    affine.linear() = bone.linear;
    affine.translation() = bone.translation;
    placement.affine[bone.bone] = affine;
  }
  scaling::ScaledAtlas carried;
  scaling::carry_atlas(*prepared, placement, carry, carried);
  carried.atlas.provenance.push_back(
      "bones fitted to their outlines on the radiographs by mmm "
      "fit_bone_outlines (" +
      bone_list(options.bones) + ")");
  context.progress(3, 5, "writing the patient's atlas");
  const std::filesystem::path out = context.scratch_dir() / "atlas_out";
  atlas::write_atlas_with_meshes(carried.atlas, carried.meshes, out, options.threads);
  context.set_output("atlas", pack_directory(out));
  nlohmann::json report = fit_report(fit);
  report["decision"] = corrections.empty() ? "fit" : "correct";
  nlohmann::json muscles = nlohmann::json::array();
  for (const scaling::MuscleScaling& muscle : carried.muscles) {
    muscles.push_back({{"muscle", muscle.muscle}, {"volume_ratio", muscle.solution.volume_ratio}});
  }
  report["muscles"] = muscles;
  report["total_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  context.set_output("report", report.dump(2));
  context.progress(4, 5, "drawing the overlay");
  const std::filesystem::path overlay = context.scratch_dir() / "overlay.png";
  image::write_png(overlay_picture(start, start_meshes, carried.meshes, fit, pair), overlay);
  context.set_output_file("overlay", overlay);
  context.progress(5, 5, "done");
}

}  // namespace mmm::nodes
