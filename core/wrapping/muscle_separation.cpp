#include "core/wrapping/muscle_separation.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>

#include "core/errors.h"
#include "core/parallel_for.h"

namespace mmm::wrapping {
namespace {

// Deepest vertex of every muscle inside another one (mm).
std::vector<double> deepest_overlaps(const std::vector<Eigen::MatrixX3d>& positions,
                                     const MuscleSurfaces& surfaces, double tolerance_mm,
                                     int threads) {
  std::vector<double> deepest(positions.size(), 0.0);
  parallel_for(positions.size(), threads, [&](std::size_t m) {
    deepest[m] =
        measure_muscle_penetration(static_cast<int>(m), positions[m], surfaces, {}, tolerance_mm)
            .max_depth_mm;
  });
  return deepest;
}

}  // namespace

MuscleSeparation separate_muscles(const std::vector<mesh::IndexedMesh>& surfaces,
                                  const std::vector<PosableBone>& bones,
                                  const SeparationOptions& options, int threads) {
  if (options.max_rounds < 1) throw InvalidInputError("muscle separation: max_rounds must be >= 1");
  const auto start = std::chrono::steady_clock::now();
  const std::size_t muscles = surfaces.size();
  std::vector<const Eigen::MatrixX3i*> faces;
  MuscleSeparation result;
  for (const mesh::IndexedMesh& surface : surfaces) {
    faces.push_back(&surface.F);
    result.positions.push_back(surface.V);
  }
  const double tolerance = options.contact.tolerance_mm;
  // The surfaces as they stand: measured, then the next round's obstacles.
  auto now = std::make_unique<MuscleSurfaces>(result.positions, faces, threads);
  result.overlap_before_mm = deepest_overlaps(result.positions, *now, tolerance, threads);

  // Deformers and bone contacts only for the muscles that get pins (made
  // when they first do): the others stay exactly as they are.
  std::vector<std::unique_ptr<VolumeDeformer>> deformers(muscles);
  std::vector<std::unique_ptr<BoneContacts>> bone_contacts(muscles);
  const std::vector<Eigen::Isometry3d> at_rest(bones.size(), Eigen::Isometry3d::Identity());
  MusclePins pins(muscles);
  for (int round = 0; round < options.max_rounds; ++round) {
    MuscleContactOptions round_contact = options.contact;
    round_contact.share = round_share(round_contact.share, round, options.max_rounds);
    if (!pins.add(shared_muscle_contacts(result.positions, *now, round_contact, threads))) break;
    result.rounds = round + 1;
    parallel_for(muscles, threads, [&](std::size_t m) {
      if (pins.empty(m)) return;
      if (!deformers[m]) {
        deformers[m] = std::make_unique<VolumeDeformer>(surfaces[m], options.deformer);
        if (!bones.empty()) {
          bone_contacts[m] =
              std::make_unique<BoneContacts>(surfaces[m].V, bones, options.bone_contacts);
        }
      }
      ContactQuery query;
      if (bone_contacts[m]) {
        query = [&](const Eigen::MatrixX3d& x, const std::vector<char>& active) {
          return bone_contacts[m]->find(x, at_rest, active);
        };
      }
      result.positions[m] = deformers[m]->solve(surfaces[m].V, {}, pins.of(m), query).x;
    });
    now = std::make_unique<MuscleSurfaces>(result.positions, faces, threads);
  }
  result.overlap_after_mm = deepest_overlaps(result.positions, *now, tolerance, threads);
  for (std::size_t m = 0; m < muscles; ++m) {
    result.max_move_mm.push_back((result.positions[m] - surfaces[m].V).rowwise().norm().maxCoeff());
    const double rest = enclosed_volume(surfaces[m].V, surfaces[m].F);
    result.volume_error_percent.push_back(
        100.0 * (enclosed_volume(result.positions[m], surfaces[m].F) - rest) / rest);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace mmm::wrapping
