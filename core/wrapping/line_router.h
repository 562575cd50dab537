#pragma once
// One action line followed over a motion: its path in each pose, by the
// obstacle-set method (action_line_path.h: straight segments between the
// path points, wrapped over the line's fitted obstacles) or by the global
// method (global_path.h: the shortest path through the same path points that
// keeps a clearance from the bone meshes themselves), and its moment arms.
//
// The global path of each pose starts from the previous one (warm start), so
// routing a motion frame by frame follows the same side of every bone; the
// moment arm -dL/dq is a central difference of two paths warm-started from
// the current one (step moment_arm_step_rad: the discrete path's length is
// smooth only to the optimiser's tolerance, so a step much smaller than the
// obstacle-set's would differentiate noise).

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/signed_distance.h"
#include "core/motion/skeleton.h"
#include "core/wrapping/action_line_path.h"
#include "core/wrapping/global_path.h"

namespace mmm::wrapping {

enum class PathMethod { kObstacleSet, kGlobal };

// A bone surface the global path keeps clear of: its signed distance in the
// atlas's rest frame and the skeleton body that carries it.
struct RoutingBone {
  const mesh::SignedDistance* sdf = nullptr;  // not owned
  int body = -1;
};

struct RouterOptions {
  PathMethod method = PathMethod::kObstacleSet;
  PathOptions path;                   // the path points and obstacles; obstacle-set moment arms
  GlobalPathOptions global;           // the global method
  double moment_arm_step_rad = 0.01;  // global method: central-difference step
};

class LineRouter {
 public:
  // `skeleton` built from `atlas` (motion::skeleton_from_atlas: a body's
  // pose carries its bone from the atlas frame to the world); `bones` are
  // used by the global method only. References must outlive the router.
  LineRouter(const atlas::Atlas& atlas, const atlas::Muscle& muscle, const atlas::ActionLine& line,
             const motion::Skeleton& skeleton, std::vector<RoutingBone> bones,
             const RouterOptions& options);

  // The path at coordinates q. Global method: warm-started from the last
  // route() and remembered for the next. Throws as action_line_path and
  // global_path.
  ActionLinePath route(const Eigen::VectorXd& q);

  // -dL/dq about `coordinate` at q (mm per rad, or per mm). Does not change
  // the remembered path.
  double moment_arm(const Eigen::VectorXd& q, int coordinate);

  // Global method: the interior points of the last path that rest on a bone
  // (within clearance + tolerance), for the report; 0 for the obstacle set.
  [[nodiscard]] int last_contacts() const { return last_contacts_; }

 private:
  ActionLinePath global_route(const Eigen::VectorXd& q, const GlobalPath* warm,
                              GlobalPath* result) const;

  const atlas::Atlas& atlas_;
  const atlas::Muscle& muscle_;
  const atlas::ActionLine& line_;
  const motion::Skeleton& skeleton_;
  std::vector<RoutingBone> bones_;
  RouterOptions options_;
  std::optional<GlobalPath> last_;
  int last_contacts_ = 0;
};

}  // namespace mmm::wrapping
