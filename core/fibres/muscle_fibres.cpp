#include "core/fibres/muscle_fibres.h"

#include <array>
#include <chrono>
#include <string>

#include "core/errors.h"
#include "core/fibres/cadaver_fibres.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/harmonic_decomposition.h"
#include "core/fibres/harmonic_field.h"
#include "core/fibres/mass_spring_decomposition.h"
#include "core/fibres/slicing_decomposition.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::fibres {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Index;

constexpr std::array<std::string_view, 4> kMethodNames = {"slicing", "harmonic", "mass_spring",
                                                          "cadaver"};
constexpr int kStandIns = 4;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Each measured point re-expressed on the surface at `positions`: the same
// face and barycentric weights as its closest point on the rest surface.
std::vector<Fibre> carry_measured(const std::vector<Fibre>& measured, const mesh::IndexedMesh& rest,
                                  const Eigen::MatrixX3d& positions) {
  const mesh::AabbTree tree(rest);
  std::vector<Fibre> carried;
  for (const Fibre& fibre : measured) {
    Fibre moved(fibre.rows(), 3);
    for (Index k = 0; k < fibre.rows(); ++k) {
      const mesh::AabbTree::ClosestPoint c = tree.closest_point(fibre.row(k).transpose());
      moved.row(k).setZero();
      for (int corner = 0; corner < 3; ++corner) {
        moved.row(k) += c.barycentric(corner) * positions.row(rest.F(c.face, corner));
      }
    }
    carried.push_back(std::move(moved));
  }
  return carried;
}

// Stand-ins for measured fibres: harmonic fibres of the template's first row
// (one side of the muscle), spread across it, moved onto the surface. A
// fibre whose ends pair crosswise with the first one's (a twisted harmonic
// fibre) is left out.
std::vector<Fibre> stand_in_measured(const mesh::IndexedMesh& surface,
                                     const std::vector<Fibre>& harmonic, int row_length) {
  const mesh::AabbTree tree(surface);
  std::vector<Fibre> measured;
  for (int i = 0; i < kStandIns; ++i) {
    const auto column = static_cast<std::size_t>(
        std::lround(static_cast<double>(i * (row_length - 1)) / (kStandIns - 1)));
    Fibre fibre = harmonic.at(column);
    for (Index k = 0; k < fibre.rows(); ++k) {
      fibre.row(k) = tree.closest_point(fibre.row(k).transpose()).point.transpose();
    }
    if (!measured.empty()) {
      const Fibre& first = measured.front();
      const auto end = [](const Fibre& f, bool last) {
        return Eigen::Vector3d(f.row(last ? f.rows() - 1 : 0).transpose());
      };
      const double straight = (end(fibre, false) - end(first, false)).norm() +
                              (end(fibre, true) - end(first, true)).norm();
      const double crossed = (end(fibre, false) - end(first, true)).norm() +
                             (end(fibre, true) - end(first, false)).norm();
      if (crossed < straight) continue;
    }
    measured.push_back(std::move(fibre));
  }
  return measured;
}

}  // namespace

std::string_view method_name(DecompositionMethod method) {
  return kMethodNames.at(static_cast<std::size_t>(method));
}

std::optional<DecompositionMethod> method_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kMethodNames.size(); ++i) {
    if (kMethodNames[i] == name) return static_cast<DecompositionMethod>(i);
  }
  return std::nullopt;
}

MuscleFibreModel::MuscleFibreModel(std::string name, mesh::IndexedMesh rest,
                                   MuscleAttachmentSamples samples, DecompositionMethod method,
                                   const DecompositionOptions& options, std::vector<Fibre> measured)
    : name_(std::move(name)),
      rest_(std::move(rest)),
      samples_(std::move(samples)),
      method_(method),
      options_(options),
      measured_(std::move(measured)) {
  validate(options_);
  if (method_ == DecompositionMethod::kCadaver && measured_.size() == 1) {
    throw InvalidInputError("muscle " + name_ +
                            ": one measured fibre; the cadaver method needs at least two");
  }
  try {
    ends_ = fibres::end_patches(rest_, posed_attachments(samples_));
    if (method_ == DecompositionMethod::kHarmonic || method_ == DecompositionMethod::kCadaver) {
      const auto start = Clock::now();
      field_ = harmonic_field(rest_, ends_);
      field_seconds_ = seconds_since(start);
    }
  } catch (const InvalidInputError& error) {
    throw InvalidInputError("muscle " + name_ + ": " + error.what());
  }
}

MuscleFibres MuscleFibreModel::decompose(const Eigen::MatrixX3d& positions,
                                         const BonePose& pose) const {
  if (positions.rows() != rest_.V.rows()) {
    throw InvalidInputError("muscle " + name_ + ": " + std::to_string(positions.rows()) +
                            " vertices given for a surface of " + std::to_string(rest_.V.rows()) +
                            "; the frames must come from the same wrapping resolution");
  }
  try {
    return decompose_checked(positions, pose);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError("muscle " + name_ + " (" + std::string(method_name(method_)) +
                            "): " + error.what());
  }
}

MuscleFibres MuscleFibreModel::decompose_checked(const Eigen::MatrixX3d& positions,
                                                 const BonePose& pose) const {
  const auto start = Clock::now();
  mesh::IndexedMesh surface{positions, rest_.F};
  MuscleFibres out;
  out.bone_areas = posed_attachments(samples_, pose);
  out.attachments = patch_attachments(ends_, positions, out.bone_areas);
  out.origin_gap_mm = patch_gap(ends_.origin, positions, out.bone_areas.origin);
  out.insertion_gap_mm = patch_gap(ends_.insertion, positions, out.bone_areas.insertion);
  const auto take = [&out](ContourFibres&& r) {
    out.fibres = std::move(r.fibres);
    out.moved_inside = r.moved_inside;
    out.interpolated_contours = r.interpolated_contours;
  };
  switch (method_) {
    case DecompositionMethod::kSlicing:
      take(slicing_fibres(surface, out.attachments, options_));
      break;
    case DecompositionMethod::kHarmonic:
      take(harmonic_fibres(surface, out.attachments, field_, options_));
      break;
    case DecompositionMethod::kMassSpring:
      take(mass_spring_decomposition(surface, out.attachments, options_));
      break;
    case DecompositionMethod::kCadaver: {
      std::vector<Fibre> measured;
      if (measured_.empty()) {
        DecompositionOptions parallel = options_;
        parallel.architecture = atlas::FibreArchitecture::kParallel;
        const HarmonicResult r = harmonic_fibres(surface, out.attachments, field_, parallel);
        const int row_length =
            static_cast<int>(std::ceil(std::sqrt(static_cast<double>(options_.fibres)) - 1e-9));
        measured = stand_in_measured(surface, r.fibres, row_length);
        out.stand_in_measured = true;
      } else {
        measured = carry_measured(measured_, rest_, positions);
      }
      CadaverFibreOptions cadaver;
      cadaver.segments = options_.segments;
      const int side = std::max(
          2, static_cast<int>(std::lround(std::sqrt(static_cast<double>(options_.fibres)))));
      cadaver.surface_fibres = side;
      cadaver.depth_layers = side;
      out.fibres = cadaver_fibres(surface, measured, cadaver).fibres;
      out.moved_inside = connect_to_nearest_attachments(
          out.fibres, surface, out.attachments, options_.segments, options_.smoothing_passes);
      break;
    }
  }
  out.seconds = seconds_since(start);
  return out;
}

}  // namespace mmm::fibres
