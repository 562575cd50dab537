#pragma once
// Where the skeleton carries each vertex of a muscle surface: the targets and
// rotations of the volume-preserving deformation (volume_deformer.h).
//
// At rest every vertex X is bound to its muscle's action lines (closest point
// on each rest path: arc-length fraction a, distance d; lines weighted by
// 1 / (d + 5 mm)^2) and, when it lies within `attachment_band_mm` of a bone
// the muscle attaches to, to that bone. In a frame:
//
//   line target   c_t(a) + R(a) (X - c_0(a)),  c the path point at fraction
//                 a of its length (so a stretched line stretches the muscle
//                 along it), R(a) = R_align * R_bones(a): the carrying bones'
//                 rotation (that of the bones of the path points on either
//                 side of a, spherically interpolated; without per-point
//                 bones, origin bone's at a = 0 to insertion bone's at a = 1)
//                 followed by the smallest
//                 rotation taking the so-turned rest tangent to the current
//                 one; tangents are chords over +-`tangent_window_mm` of arc
//                 length, smooth across the path's kinks
//   bone target   the attachment bone's rigid motion of X
//   blend         bone target within attachment_band_mm / 4 of the bone,
//                 line target beyond attachment_band_mm, smoothly between
//
// and the vertex's detail rotation is blended the same way.

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace mmm::wrapping {

struct BindingOptions {
  double attachment_band_mm = 8.0;  // > 0
  double tangent_window_mm = 15.0;  // > 0
  double line_softening_mm = 5.0;   // > 0: d offset in the line weights
  // Neighbour averages of the fractions and line weights over the surface:
  // the closest point on a kinked path jumps between segments, its fraction
  // and the targets with it; smoothed, the targets are continuous.
  int smoothing_iterations = 0;  // >= 0 (0: none; more shifts the attachments)
};

// A bone the muscle attaches to, as the binding sees it: its index in the
// caller's pose list and the rest distance of every vertex to it (mm; >= 0,
// +infinity when far).
struct AttachmentBone {
  int pose_index = -1;
  Eigen::VectorXd rest_distance;
};

// One action line in one pose: its path and the indices (in the caller's
// pose list) of the bones carrying its first and last point.
struct LinePath {
  std::vector<Eigen::Vector3d> points;  // >= 2, world (mm)
  int origin_pose_index = -1;
  int insertion_pose_index = -1;
  // Optional, one per point: the bone carrying it. The rotation carrying a
  // vertex is then interpolated between the bones of the two path points
  // around its fraction (a vastus stays with the femur until its line
  // crosses the knee), not between origin and insertion.
  std::vector<int> point_pose_indices;
  // Optional, one per point: the path point's name ("" for points of a wrap).
  // Arc lengths are then mapped between the named points present both at
  // rest and now, so a conditional point switching on or off moves only the
  // part of the muscle around it; without names, by fraction of the length.
  std::vector<std::string> point_names;
};

class MuscleBinding {
 public:
  // rest_vertices  #V by 3, the muscle at rest (atlas frame, mm)
  // faces          its triangles (for the smoothing)
  // rest_lines     the action lines' rest paths (at least one; in the same frame)
  // attachments    bones the muscle attaches to (may be empty)
  // Throws InvalidInputError when a line has fewer than 2 points or zero
  // length, sizes disagree, or the options are not positive.
  MuscleBinding(Eigen::MatrixX3d rest_vertices, const Eigen::MatrixX3i& faces,
                const std::vector<LinePath>& rest_lines, std::vector<AttachmentBone> attachments,
                const BindingOptions& options = {});

  struct Targets {
    Eigen::MatrixX3d positions;              // #V by 3 (mm)
    std::vector<Eigen::Matrix3d> rotations;  // #V
  };
  // lines: the same action lines, in order, in this frame; poses: every
  // bone's rest -> frame rigid motion, indexed as in the LinePaths and
  // AttachmentBones. Throws InvalidInputError on a count mismatch or an
  // index outside `poses`.
  [[nodiscard]] Targets targets(const std::vector<LinePath>& lines,
                                const std::vector<Eigen::Isometry3d>& poses) const;

  [[nodiscard]] Eigen::Index num_vertices() const { return rest_.rows(); }
  // Per vertex: 1 where it moves with its attachment bone, 0 where with the
  // lines, smoothly between (the blend above).
  [[nodiscard]] const Eigen::VectorXd& bone_blend() const { return bone_blend_; }

 private:
  struct LineBinding {
    std::vector<Eigen::Vector3d> rest_points;
    std::vector<double> rest_arc;  // cumulative arc length
    std::vector<std::string> rest_names;
    Eigen::VectorXd fraction;  // per vertex
    Eigen::VectorXd weight;    // per vertex, normalised over lines
  };
  Eigen::MatrixX3d rest_;
  std::vector<LineBinding> lines_;
  std::vector<AttachmentBone> attachments_;
  Eigen::VectorXi nearest_attachment_;  // -1: none within the band
  Eigen::VectorXd bone_blend_;          // 1: the bone's motion, 0: the lines'
  BindingOptions options_;
};

}  // namespace mmm::wrapping
