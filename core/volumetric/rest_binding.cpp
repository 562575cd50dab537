#include "core/volumetric/rest_binding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/parallel_for.h"

namespace mmm::volumetric {

MuscleSurface muscle_surface(const TetMesh& output, std::uint16_t label) {
  const mesh::IndexedMesh boundary = label_boundary(output, label);
  MuscleSurface out;
  std::vector<int> vertex(static_cast<std::size_t>(output.V.rows()), -1);
  out.rest.F.resize(boundary.F.rows(), 3);
  for (Eigen::Index f = 0; f < boundary.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      int& v = vertex[static_cast<std::size_t>(boundary.F(f, c))];
      if (v < 0) {
        v = static_cast<int>(out.nodes.size());
        out.nodes.push_back(boundary.F(f, c));
      }
      out.rest.F(f, c) = v;
    }
  }
  out.rest.V.resize(static_cast<Eigen::Index>(out.nodes.size()), 3);
  for (std::size_t v = 0; v < out.nodes.size(); ++v)
    out.rest.V.row(static_cast<Eigen::Index>(v)) = output.V.row(out.nodes[v]);
  return out;
}

std::vector<DrivenNode> attachments(const atlas::Muscle& muscle, const MuscleSurface& surface,
                                    const wrapping::PosedBones& bones,
                                    const std::vector<int>& taken, double reach, double& gap,
                                    int& left_out) {
  std::vector<DrivenNode> out;
  gap = 0.0;
  for (const auto* areas : {&muscle.origins, &muscle.insertions}) {
    for (const atlas::AttachmentArea& area : *areas) {
      const auto bone = bones.index.find(area.bone);
      if (bone == bones.index.end() || area.faces.empty()) continue;
      const mesh::IndexedMesh& full =
          bones.surfaces[static_cast<std::size_t>(bone->second)].surface->tree().mesh();
      mesh::IndexedMesh patch;
      patch.V = full.V;
      patch.F.resize(static_cast<Eigen::Index>(area.faces.size()), 3);
      for (std::size_t f = 0; f < area.faces.size(); ++f) {
        if (area.faces[f] < 0 || area.faces[f] >= full.F.rows()) {
          throw InvalidInputError("muscle simulation: an attachment area of '" + muscle.name +
                                  "' names face " + std::to_string(area.faces[f]) + " of bone '" +
                                  area.bone + "', which has " + std::to_string(full.F.rows()));
        }
        patch.F.row(static_cast<Eigen::Index>(f)) = full.F.row(area.faces[f]);
      }
      const mesh::AabbTree tree(patch);
      std::vector<double> distance(surface.nodes.size());
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t v = 0; v < surface.nodes.size(); ++v) {
        distance[v] = std::sqrt(
            tree.closest_point(surface.rest.V.row(static_cast<Eigen::Index>(v)).transpose())
                .squared_distance);
        nearest = std::min(nearest, distance[v]);
      }
      gap = std::max(gap, nearest);
      if (nearest > reach) {
        ++left_out;
        continue;
      }
      for (std::size_t v = 0; v < surface.nodes.size(); ++v) {
        const int node = surface.nodes[v];
        if (distance[v] <= reach && taken[static_cast<std::size_t>(node)] < 0)
          out.push_back({node, bone->second});
      }
    }
  }
  return out;
}

double move_out_of_bones(EmbeddedModel& model, const std::vector<int>& boundary_nodes,
                         const wrapping::PosedBones& bones, double clearance, double cell,
                         int threads, int& moved_count) {
  std::vector<Eigen::Vector3d> target(boundary_nodes.size());
  std::vector<char> moved(boundary_nodes.size(), 0);
  parallel_for(boundary_nodes.size(), threads, [&](std::size_t k) {
    Eigen::Vector3d p = model.output.V.row(boundary_nodes[k]).transpose();
    for (const wrapping::PosableBone& bone : bones.surfaces) {
      const mesh::SignedDistance& sdf = *bone.surface;
      const auto near = sdf.tree().closest_point_within(p, (cell + clearance) * (cell + clearance));
      if (!near) continue;
      const double length = std::sqrt(near->squared_distance);
      const bool inside = sdf.winding().is_inside(p);
      if (!inside && length >= clearance) continue;
      if (length < 1e-12) continue;
      const Eigen::Vector3d out = (inside ? -1.0 : 1.0) * (p - near->point) / length;
      p = near->point + clearance * out;
      moved[k] = 1;
    }
    target[k] = p;
  });
  std::vector<int> nodes;
  std::vector<Eigen::Vector3d> positions;
  double largest = 0.0;
  for (std::size_t k = 0; k < boundary_nodes.size(); ++k) {
    if (moved[k] == 0) continue;
    largest =
        std::max(largest, (target[k] - model.output.V.row(boundary_nodes[k]).transpose()).norm());
    nodes.push_back(boundary_nodes[k]);
    positions.push_back(target[k]);
  }
  Eigen::MatrixX3d rows(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t k = 0; k < positions.size(); ++k)
    rows.row(static_cast<Eigen::Index>(k)) = positions[k].transpose();
  move_output_nodes(model, nodes, rows);
  moved_count = static_cast<int>(nodes.size());
  return largest;
}

std::vector<DrivenNode> element_anchors(const TetMesh& elements, const wrapping::PosedBones& bones,
                                        double reach, double joint_clearance, int threads) {
  std::vector<int> bone_of(static_cast<std::size_t>(elements.V.rows()), -1);
  parallel_for(bone_of.size(), threads, [&](std::size_t i) {
    const Eigen::Vector3d p = elements.V.row(static_cast<Eigen::Index>(i)).transpose();
    for (std::size_t b = 0; b < bones.surfaces.size(); ++b) {
      const mesh::SignedDistance& sdf = *bones.surfaces[b].surface;
      if (sdf.tree().closest_point_within(p, reach * reach) && sdf.winding().is_inside(p)) {
        bone_of[i] = static_cast<int>(b);
        break;
      }
    }
    // Near a joint the tissue slides over both bones: not anchored.
    if (bone_of[i] < 0 || !(joint_clearance > 0)) return;
    for (std::size_t b = 0; b < bones.surfaces.size(); ++b) {
      if (static_cast<int>(b) == bone_of[i] ||
          bones.bodies[b] == bones.bodies[static_cast<std::size_t>(bone_of[i])]) {
        continue;
      }
      if (bones.surfaces[b].surface->tree().closest_point_within(
              p, joint_clearance * joint_clearance)) {
        bone_of[i] = -1;
        return;
      }
    }
  });
  // An element reaching into two bones (tissue between the ischium and the
  // femur, say) cannot follow both: its corners are left to the contacts.
  std::vector<char> torn(bone_of.size(), 0);
  for (Eigen::Index t = 0; t < elements.T.rows(); ++t) {
    int first = -1;
    bool two = false;
    for (int c = 0; c < 4; ++c) {
      const int bone = bone_of[static_cast<std::size_t>(elements.T(t, c))];
      if (bone < 0) continue;
      if (first >= 0 && bone != first) two = true;
      first = bone;
    }
    if (!two) continue;
    for (int c = 0; c < 4; ++c) torn[static_cast<std::size_t>(elements.T(t, c))] = 1;
  }
  std::vector<DrivenNode> out;
  for (std::size_t i = 0; i < bone_of.size(); ++i) {
    if (bone_of[i] >= 0 && torn[i] == 0) out.push_back({static_cast<int>(i), bone_of[i], true});
  }
  return out;
}

}  // namespace mmm::volumetric
