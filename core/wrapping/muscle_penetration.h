#pragma once
// Muscles running into each other: the muscle-muscle penetration metric of
// muscle wrapping, and the contacts that keep muscles apart.
//
// The metric is measured after every muscle has been solved for a frame.
// Segmented atlases overlap where two muscles were traced one by one (the
// Visible Human surfaces), so it is the penetration the motion adds: a
// vertex's depth inside another muscle minus its depth inside that muscle at
// rest (0 where it was outside). Inside tests by winding number, depths by
// exact closest point (mesh::SignedDistance); only muscles whose boxes meet
// are compared.
//
// The contacts (shared_muscle_contacts, muscle_entries) pin vertices of
// overlapping muscles for the volume-preserving solve (volume_deformer.h),
// like bone contacts but shared: both sides give way, each by its share.

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <vector>

#include "core/mesh/signed_distance.h"
#include "core/wrapping/volume_deformer.h"

namespace mmm::wrapping {

struct MuscleWrapping;

// Every muscle's surface in one pose (mm), ready for inside queries.
class MuscleSurfaces {
 public:
  // positions[m]: muscle m's vertices; faces[m] its triangles. Built on
  // `threads` threads. Throws InvalidInputError on a size mismatch or an
  // invalid mesh.
  MuscleSurfaces(const std::vector<Eigen::MatrixX3d>& positions,
                 const std::vector<const Eigen::MatrixX3i*>& faces, int threads);

  [[nodiscard]] std::size_t size() const { return surfaces_.size(); }
  [[nodiscard]] const mesh::SignedDistance& surface(std::size_t m) const { return *surfaces_[m]; }
  [[nodiscard]] const Eigen::AlignedBox3d& box(std::size_t m) const { return boxes_[m]; }
  [[nodiscard]] const Eigen::MatrixX3i& faces(std::size_t m) const {
    return surfaces_[m]->tree().mesh().F;
  }

 private:
  std::vector<std::unique_ptr<mesh::SignedDistance>> surfaces_;
  std::vector<Eigen::AlignedBox3d> boxes_;
};

// Per other muscle n: the rest depth (mm, >= 0) of each vertex of one muscle
// inside n; only muscles it overlaps at rest are listed.
using RestOverlap = std::map<int, Eigen::VectorXd>;

// The rest overlap of muscle `self` (vertices x) with the others.
RestOverlap rest_overlap(int self, const Eigen::MatrixX3d& x, const MuscleSurfaces& others);

struct MusclePenetration {
  double max_depth_mm = 0.0;  // deepest vertex beyond its rest depth in another muscle
  int vertices_deeper = 0;    // vertices deeper than that by more than the tolerance
  int deepest_muscle = -1;    // index of the muscle where max_depth_mm is reached (-1: none)
};

// Penetration of muscle `self` (vertices x) into the other muscles.
MusclePenetration measure_muscle_penetration(int self, const Eigen::MatrixX3d& x,
                                             const MuscleSurfaces& others, const RestOverlap& rest,
                                             double tolerance_mm);

// Obstacle index of a contact with muscle n (Contact::obstacle): negative,
// so that carrying bone contacts by bone poses leaves it alone.
inline int muscle_obstacle(int n) { return -2 - n; }
inline bool is_muscle_obstacle(int obstacle) { return obstacle <= -2; }

// Contacts between muscles in one pose, shared out (impenetrability between
// muscles). Wherever a vertex p of muscle m lies deeper than the tolerance
// inside muscle n (nearest point c of n's surface, on face f), the two
// surfaces are to meet between p and c: p is pinned `share` of the way to c,
// and the corners of f are pinned (1 - share) of (p - c) further into n. A
// vertex pinned several times keeps its longest move. positions[m]: muscle
// m's vertices in this pose, the ones `surfaces` was built from. Returns the
// contacts per muscle. Throws InvalidInputError for a share outside [0, 1]
// or sizes that do not match.
struct MuscleContactOptions {
  double share = 0.5;         // [0, 1]: of an overlap, what the penetrating side moves
  double tolerance_mm = 0.1;  // shallower overlaps are left alone
  double weight = 1e2;        // pinning weight (soft tissue on soft tissue: softer than bone)
  double reach_mm = 20.0;     // deeper overlaps are not looked for
};

// How far one muscle's vertices were from the others' surfaces when the
// contacts were found: per other muscle, a lower bound of each vertex's
// distance to its surface (0 inside, reach_mm beyond reach). A vertex that
// has moved less than that since `from` has not entered that surface.
struct MuscleClearance {
  Eigen::MatrixX3d from;
  std::map<int, Eigen::VectorXd> clearance;
};

// `clearances`, when given, receives each muscle's clearance.
std::vector<std::vector<Contact>> shared_muscle_contacts(
    const std::vector<Eigen::MatrixX3d>& positions, const MuscleSurfaces& surfaces,
    const MuscleContactOptions& options, int threads,
    std::vector<MuscleClearance>* clearances = nullptr);

// Each side's share of an overlap in round `round` of `rounds`: from the
// larger of share and 1 - share in the first to all of it in the last, so
// that an overlap one side cannot give way to (pressed against a bone, or
// not deformable) is still resolved by the other.
double round_share(double share, int round, int rounds);

// The longest move any of `found` asks of its vertex (mm; 0 when none):
// with all of each overlap to the entering side, the deepest entry into
// another muscle. found[m]: muscle m's contacts on positions[m]. Throws
// InvalidInputError for sizes or vertices that do not match.
double longest_move(const std::vector<std::vector<Contact>>& found,
                    const std::vector<Eigen::MatrixX3d>& positions);

// Shared contacts gathered over rounds, per muscle: a vertex keeps its latest
// pin.
class MusclePins {
 public:
  explicit MusclePins(std::size_t muscles) : pins_(muscles) {}
  // Adds one round's contacts (one list per muscle); false when there were none.
  bool add(const std::vector<std::vector<Contact>>& found);
  [[nodiscard]] std::vector<Contact> of(std::size_t muscle) const;
  [[nodiscard]] bool empty(std::size_t muscle) const { return pins_[muscle].empty(); }

 private:
  std::vector<std::map<int, Contact>> pins_;
};

// A vertex of one muscle inside another: the muscle it entered, the nearest
// point of that muscle's surface (on `face`, with barycentric weights of its
// corners F(face, 0..2)) and the depth (mm).
struct MuscleOverlap {
  int vertex = -1;
  int other = -1;
  int face = -1;
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double depth = 0.0;
};

// Vertices of muscle `self` (x) not flagged in `active` deeper than the
// tolerance (and within reach) inside another muscle of `others`, the deepest
// muscle per vertex; `clearance` spares the vertices that cannot have entered.
std::vector<MuscleOverlap> muscle_overlaps(int self, const Eigen::MatrixX3d& x,
                                           const std::vector<char>& active,
                                           const MuscleSurfaces& others,
                                           const MuscleContactOptions& options,
                                           const MuscleClearance* clearance = nullptr);

// Vertices of muscle `self` (x) not flagged in `active` that lie deeper than
// the tolerance inside another muscle of `others`, pinned to that muscle's
// nearest surface point (the deepest muscle per vertex counts): new entries
// during a solve, where the other muscle is not moving out of the way.
// `clearance` (of x's muscle against the same surfaces) spares the vertices
// that cannot have entered.
std::vector<Contact> muscle_entries(int self, const Eigen::MatrixX3d& x,
                                    const std::vector<char>& active, const MuscleSurfaces& others,
                                    const MuscleContactOptions& options,
                                    const MuscleClearance* clearance = nullptr);

// Fills muscle_depth_mm, muscle_vertices_deeper and deepest_muscle of every
// muscle-frame of `wrapped` (rest overlaps from the muscles' rest surfaces),
// frames in parallel on `threads` threads.
void measure_muscle_penetration(MuscleWrapping& wrapped, double tolerance_mm, int threads);

}  // namespace mmm::wrapping
