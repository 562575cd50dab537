#include "core/outlines/atlas_outline_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "core/atlas/kinematic_chain.h"
#include "core/errors.h"
#include "core/outlines/bone_cover.h"
#include "core/outlines/neighbour_layers.h"
#include "core/parallel_for.h"

namespace mmm::outlines {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

// The operator's landmarks on the bone, then its joint centres.
std::vector<PinnedPoint> pins_of(const atlas::Atlas& atlas, const std::string& bone,
                                 const landmarks::LandmarkSet& landmarks,
                                 const AtlasOutlineFitOptions& options) {
  std::vector<PinnedPoint> pins;
  for (const landmarks::Landmark& given : landmarks.landmarks) {
    const atlas::Landmark* landmark = atlas.find_landmark(given.name);
    if (landmark == nullptr || landmark->bone != bone) continue;
    pins.push_back(
        {"landmark " + given.name, landmark->position, given.position_mm, options.landmark_pin});
  }
  for (const atlas::Joint& joint : atlas.joints) {
    if (joint.type == atlas::JointType::kWeld) continue;
    if (joint.child == bone) {
      const Eigen::Vector3d centre = joint.child_frame.translation();
      pins.push_back({"joint " + joint.name, centre, centre, options.joint_pin});
    } else if (joint.parent == bone) {
      const Eigen::Vector3d centre = joint.parent_frame.translation();
      pins.push_back({"joint " + joint.name, centre, centre, options.joint_pin});
    }
  }
  return pins;
}

}  // namespace

AtlasOutlineFit fit_atlas_outlines(const atlas::Atlas& atlas, const atlas::AtlasMeshes& meshes,
                                   const landmarks::LandmarkSet& landmarks,
                                   const image::RadiographPair& pair,
                                   const std::vector<OutlineCorrection>& corrections,
                                   const AtlasOutlineFitOptions& options) {
  std::vector<std::string> atlas_bones;
  for (const atlas::Bone& bone : atlas.bones) atlas_bones.push_back(bone.name);
  std::vector<const atlas::Bone*> chosen;
  for (const std::string& name : options.bones) {
    const atlas::Bone* bone = atlas.find_bone(name);
    if (bone == nullptr) {
      throw InvalidInputError("outline fit: bone '" + name + "' is not in atlas " + atlas.name +
                              "; hint: its bones are " + joined(atlas_bones));
    }
    chosen.push_back(bone);
  }
  for (const auto& [name, factor] : options.membrane_factor) {
    if (!(factor > 0) || !std::isfinite(factor)) {
      throw InvalidInputError("outline fit: the membrane factor of bone '" + name +
                              "' is not a positive number; hint: e.g. 3");
    }
  }
  for (const auto& [name, factor] : options.thickness_factor) {
    if (!(factor >= 0) || !std::isfinite(factor)) {
      throw InvalidInputError("outline fit: the thickness factor of bone '" + name +
                              "' is not a number >= 0; hint: 0 turns the term off for it");
    }
  }
  const std::vector<image::RadiographView> views = pair.calibrated_views();
  std::vector<std::string> view_names;
  view_names.reserve(views.size());
  for (const image::RadiographView& view : views) view_names.push_back(view.name);
  for (const OutlineCorrection& correction : corrections) {
    if (std::ranges::find(options.bones, correction.bone) == options.bones.end()) {
      throw InvalidInputError("outline fit: a correction names bone '" + correction.bone +
                              "', which is not fitted; hint: the fitted bones are " +
                              joined(options.bones));
    }
    if (std::ranges::find(view_names, correction.view) == view_names.end()) {
      throw InvalidInputError("outline fit: a correction names view '" + correction.view +
                              "'; hint: the views are " + joined(view_names));
    }
  }

  // An element's work level, else its full one; null when the atlas has no mesh for it.
  const auto work_mesh = [&](const std::string& name) -> const mesh::IndexedMesh* {
    const auto levels = meshes.find(name);
    if (levels == meshes.end()) return nullptr;
    const auto level = levels->second.find(options.work_level);
    return level != levels->second.end() ? &level->second : &levels->second.at("full");
  };
  AtlasOutlineFit result;
  auto start = std::chrono::steady_clock::now();
  // One edge image per view and distinct stage sigma.
  std::vector<double> sigmas;
  for (const OutlineFitStage& stage : options.fit.stages) {
    if (std::ranges::find(sigmas, stage.sigma_px) == sigmas.end()) sigmas.push_back(stage.sigma_px);
  }
  // Per view and sigma (index v * sigmas + s), smoothed in parallel.
  const auto smoothed = [&](const std::vector<image::GrayImage16>& radiographs) {
    std::vector<std::unique_ptr<EdgeImage>> out(radiographs.size() * sigmas.size());
    parallel_for(out.size(), options.threads, [&](std::size_t k) {
      out[k] =
          std::make_unique<EdgeImage>(radiographs[k / sigmas.size()], sigmas[k % sigmas.size()]);
    });
    return out;
  };
  // View v's image for each stage, in stage order.
  const auto stage_edges = [&](const std::vector<std::unique_ptr<EdgeImage>>& smooth,
                               std::size_t v) {
    std::vector<const EdgeImage*> edges;
    for (const OutlineFitStage& stage : options.fit.stages) {
      const auto s =
          static_cast<std::size_t>(std::ranges::find(sigmas, stage.sigma_px) - sigmas.begin());
      edges.push_back(smooth[v * sigmas.size() + s].get());
    }
    return edges;
  };
  std::vector<image::GrayImage16> radiographs(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) radiographs[v] = pair.image(views[v].name);
  const std::vector<std::unique_ptr<EdgeImage>> images = smoothed(radiographs);
  std::vector<FitView> fit_views(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) {
    fit_views[v].view = &views[v];
    fit_views[v].edges = stage_edges(images, v);
  }
  // Where the bones lie on each view at the start, for the thickness term.
  std::vector<std::vector<std::uint8_t>> covers(views.size());
  std::vector<SoftTissueImage> soft;
  // The soft tissue's model serves the thickness term and the bones whose
  // outlines are sought without it.
  const bool model_tissue = options.soft_tissue_model && (options.fit.thickness.weight > 0 ||
                                                          !options.tissue_free_bones.empty());
  if (options.fit.thickness.weight > 0 || model_tissue) {
    std::vector<const mesh::IndexedMesh*> surfaces;
    for (const atlas::Bone& bone : atlas.bones) {
      if (const mesh::IndexedMesh* surface = work_mesh(bone.name)) surfaces.push_back(surface);
    }
    parallel_for(views.size(), options.threads,
                 [&](std::size_t v) { covers[v] = count_cover(surfaces, views[v]); });
    for (std::size_t v = 0; v < views.size(); ++v) fit_views[v].cover = &covers[v];
    if (model_tissue && !surfaces.empty()) {
      std::vector<const mesh::IndexedMesh*> muscles;
      for (const atlas::Muscle& muscle : atlas.muscles) {
        if (const mesh::IndexedMesh* surface = work_mesh(muscle.name)) muscles.push_back(surface);
      }
      std::vector<const EdgeImage*> smooth;
      smooth.reserve(fit_views.size());
      // The finest stage's image: the least blur against the model's sharp edges.
      for (const FitView& view : fit_views) smooth.push_back(view.edges.back());
      SoftTissueModelOptions model = options.soft_tissue;
      model.threads = options.threads;
      soft = model_soft_tissue(surfaces, muscles, views, smooth, model);
      for (std::size_t v = 0; v < views.size(); ++v) {
        const SoftTissueImage& law = soft[v];
        fit_views[v].soft = &law;
        result.soft_tissue.push_back({views[v].name, law.usable(), law.offset, law.tissue_per_mm,
                                      law.muscle_per_mm, law.samples, law.residual_rms,
                                      law.rows_matched, law.median_width_ratio});
      }
    }
  }
  // The same views over the radiographs without the modelled soft tissue.
  std::vector<std::unique_ptr<EdgeImage>> tissue_free_images;
  std::vector<FitView> tissue_free_views;
  if (!options.tissue_free_bones.empty() && soft.size() == views.size()) {
    std::vector<image::GrayImage16> tissue_free(views.size());
    parallel_for(views.size(), options.threads, [&](std::size_t v) {
      tissue_free[v] = without_soft_tissue(radiographs[v], soft[v]);
    });
    tissue_free_images = smoothed(tissue_free);
    tissue_free_views = fit_views;
    for (std::size_t v = 0; v < views.size(); ++v) {
      tissue_free_views[v].soft = nullptr;
      tissue_free_views[v].edges = stage_edges(tissue_free_images, v);
    }
  }
  result.images_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  result.bones.resize(chosen.size());
  const auto fit_one = [&](std::size_t index, const std::vector<FitView>& bone_views) {
    const auto bone_start = std::chrono::steady_clock::now();
    const atlas::Bone& bone = *chosen[index];
    const auto& levels = meshes.at(bone.name);
    BoneOutlineInput input;
    input.bone = bone.name;
    input.full = &levels.at("full");
    input.work =
        levels.contains(options.work_level) ? &levels.at(options.work_level) : &levels.at("full");
    input.pins = pins_of(atlas, bone.name, landmarks, options);
    for (const OutlineCorrection& correction : corrections) {
      if (correction.bone != bone.name) continue;
      const int view =
          static_cast<int>(std::ranges::find(view_names, correction.view) - view_names.begin());
      for (const Eigen::Vector2d& point : correction.points_px) {
        input.corrections.push_back({view, point});
      }
    }
    OutlineFitOptions fit = options.fit;
    if (const auto factor = options.membrane_factor.find(bone.name);
        factor != options.membrane_factor.end()) {
      fit.smoothness_weight *= factor->second;
    }
    if (const auto spacing = options.node_spacing_mm.find(bone.name);
        spacing != options.node_spacing_mm.end()) {
      fit.node_spacing_mm = spacing->second;
    }
    if (const auto factor = options.thickness_factor.find(bone.name);
        factor != options.thickness_factor.end()) {
      fit.thickness.weight *= factor->second;
    }
    BoneOutlineFit fitted = fit_bone_outline(input, bone_views, fit);
    fitted.seconds = seconds_since(bone_start);
    return fitted;
  };
  const auto views_of = [&](const std::string& bone) -> const std::vector<FitView>& {
    const bool tissue_free =
        !tissue_free_views.empty() &&
        std::ranges::find(options.tissue_free_bones, bone) != options.tissue_free_bones.end();
    return tissue_free ? tissue_free_views : fit_views;
  };
  // The rounds, as indices into `chosen`: "*" stands for every bone no round
  // names. Without the thickness term there are no gains to take a bone out
  // with, so every bone is fitted once, in one round.
  std::vector<std::vector<std::size_t>> plan;
  {
    const auto named = [&](const std::string& name) {
      return std::ranges::any_of(options.rounds, [&](const std::vector<std::string>& round) {
        return std::ranges::find(round, name) != round.end();
      });
    };
    const bool layered = options.fit.thickness.weight > 0 && !options.rounds.empty();
    std::vector<bool> fitted(chosen.size(), false);
    for (const std::vector<std::string>& round : options.rounds) {
      std::vector<std::size_t> members;
      for (std::size_t i = 0; i < chosen.size(); ++i) {
        const std::string& name = chosen[i]->name;
        const bool listed = std::ranges::find(round, name) != round.end() ||
                            (std::ranges::find(round, "*") != round.end() && !named(name));
        if (listed && (layered || !fitted[i])) members.push_back(i);
      }
      for (const std::size_t i : members) fitted[i] = true;
      if (!members.empty()) plan.push_back(std::move(members));
    }
    std::vector<std::size_t> rest;
    for (std::size_t i = 0; i < chosen.size(); ++i) {
      if (!fitted[i]) rest.push_back(i);
    }
    if (!rest.empty()) plan.insert(plan.begin(), std::move(rest));
  }
  std::vector<std::pair<std::string, const mesh::IndexedMesh*>> bone_surfaces;
  for (const atlas::Bone& bone : atlas.bones) {
    if (const mesh::IndexedMesh* surface = work_mesh(bone.name)) {
      bone_surfaces.emplace_back(bone.name, surface);
    }
  }
  // The layer reaches as far as the first stage's search around the bone.
  const double margin_mm = options.fit.stages.front().reach_mm + 10.0;
  std::vector<bool> have_fit(chosen.size(), false);
  for (std::vector<std::size_t>& round : plan) {
    // Largest bones first, so that two threads end together.
    std::ranges::sort(round, [&](std::size_t a, std::size_t b) {
      return meshes.at(chosen[a]->name).at("full").V.rows() >
             meshes.at(chosen[b]->name).at("full").V.rows();
    });
    // Every bone's latest fit, taken out of the images of the others.
    std::vector<std::pair<std::string, const BoneOutlineFit*>> done;
    for (std::size_t i = 0; i < chosen.size(); ++i) {
      if (have_fit[i]) done.emplace_back(chosen[i]->name, &result.bones[i]);
    }
    const NeighbourLayers layers(done, meshes, bone_surfaces, views);
    std::vector<BoneOutlineFit> fits(round.size());
    parallel_for(round.size(), options.threads, [&](std::size_t k) {
      const std::string& name = chosen[round[k]]->name;
      if (done.empty()) {
        fits[k] = fit_one(round[k], views_of(name));
        return;
      }
      NeighbourViews own;
      layers.fill(own, name, *work_mesh(name), views_of(name), margin_mm);
      fits[k] = fit_one(round[k], own.views);
      fits[k].neighbours_removed_px = own.pixels_removed;
      if (std::ranges::all_of(own.pixels_removed, [](int n) { return n == 0; })) {
        fits[k].neighbours_removed_px.clear();
      }
    });
    for (std::size_t k = 0; k < round.size(); ++k) {
      const double before = have_fit[round[k]] ? result.bones[round[k]].seconds : 0.0;
      result.bones[round[k]] = std::move(fits[k]);
      result.bones[round[k]].seconds += before;
      have_fit[round[k]] = true;
    }
  }
  result.fit_seconds = seconds_since(start);
  for (const atlas::Bone& bone : atlas.bones) {
    if (std::ranges::find(options.bones, bone.name) == options.bones.end()) {
      result.not_fitted.push_back(bone.name);
    }
  }
  return result;
}

}  // namespace mmm::outlines
