#include "core/volumetric/labelled_lattice.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/mesh/aabb_tree.h"
#include "core/mesh/mass_properties.h"
#include "core/parallel_for.h"

namespace mmm::volumetric {
namespace {

using Eigen::Vector3d;

constexpr std::uint16_t kBone = std::numeric_limits<std::uint16_t>::max();
constexpr std::size_t kMaxMuscles = kBone - 1;

struct Body {
  std::string name;
  std::unique_ptr<mesh::AabbTree> tree;
  Eigen::AlignedBox3d box;
  double volume = 0.0;
};

Body prepare(const NamedSurface& named, const char* kind) {
  const std::string what = std::string(kind) + " '" + named.name + "'";
  if (named.surface == nullptr || named.surface->empty()) {
    throw InvalidInputError(what + ": no surface (give its closed triangle mesh)");
  }
  Body body;
  body.name = named.name;
  try {
    body.tree = std::make_unique<mesh::AabbTree>(*named.surface);
  } catch (const InvalidInputError& e) {
    throw InvalidInputError(what + ": " + e.what());
  }
  body.box = body.tree->bounds();
  body.volume = mesh::signed_volume(*named.surface);
  if (!(body.volume > 0)) {
    throw InvalidInputError(what + ": its surface encloses no volume (" +
                            std::to_string(body.volume) +
                            " mm^3; it must be closed and face outwards)");
  }
  return body;
}

// The cells of column (i, j) inside `body`, in k: calls inside(k) for each.
// A ray along +z through the column's centre (nudged off the grid's planes,
// so that it does not run along the edges of a surface built on the same
// grid) counts entries minus exits below each cell centre.
template <typename Inside>
void fill_column(const Body& body, const LabelledLattice& lattice, int i, int j, int k_lo, int k_hi,
                 const Inside& inside) {
  const double h = lattice.spacing_mm;
  const Vector3d centre = lattice.centre(i, j, 0);
  const Vector3d origin(centre.x() + 1.3e-6 * h, centre.y() + 0.7e-6 * h, body.box.min().z() - h);
  const Vector3d up = Vector3d::UnitZ();
  const std::vector<mesh::AabbTree::RayHit> hits =
      body.tree->all_hits(origin, up, body.box.sizes().z() + 2.0 * h);
  if (hits.empty()) return;
  const mesh::IndexedMesh& surface = body.tree->mesh();
  std::vector<std::pair<double, int>> steps;  // z, +1 entering / -1 leaving
  steps.reserve(hits.size());
  for (const mesh::AabbTree::RayHit& hit : hits) {
    const Vector3d a = surface.V.row(surface.F(hit.face, 0)).transpose();
    const Vector3d b = surface.V.row(surface.F(hit.face, 1)).transpose();
    const Vector3d c = surface.V.row(surface.F(hit.face, 2)).transpose();
    const double facing = (b - a).cross(c - a).z();
    if (facing == 0.0) continue;
    steps.emplace_back(origin.z() + hit.t, facing < 0 ? 1 : -1);
  }
  std::size_t next = 0;
  int depth = 0;
  for (int k = k_lo; k <= k_hi; ++k) {
    const double z = lattice.centre(i, j, k).z();
    while (next < steps.size() && steps[next].first <= z) depth += steps[next++].second;
    if (depth > 0) inside(k);
  }
}

// Cell ranges of a box, clipped to the lattice.
struct CellRange {
  Eigen::Array3i lo;
  Eigen::Array3i hi;  // inclusive
};

CellRange cells_of(const Eigen::AlignedBox3d& box, const LabelledLattice& lattice) {
  CellRange range;
  for (int axis = 0; axis < 3; ++axis) {
    const double h = lattice.spacing_mm;
    range.lo[axis] = std::max(
        0, static_cast<int>(std::floor((box.min()[axis] - lattice.origin[axis]) / h - 0.5)));
    range.hi[axis] =
        std::min(lattice.cells[axis] - 1,
                 static_cast<int>(std::ceil((box.max()[axis] - lattice.origin[axis]) / h - 0.5)));
  }
  return range;
}

struct Regrowth {
  std::int64_t cells = 0;
  double depth_mm = 0.0;
};

// Grows each muscle with fewer cells than its segmentation's volume back
// into the free cells next to it (see the header), in rounds of one layer.
std::vector<Regrowth> regrow(LabelledLattice& lattice, const std::vector<Body>& muscles,
                             const LatticeOptions& options, std::uint16_t bone) {
  const std::size_t n = muscles.size();
  std::vector<Regrowth> out(n);
  const double h = lattice.spacing_mm;
  const int rounds = static_cast<int>(std::ceil(options.max_regrowth_mm / h));
  if (rounds == 0) return out;
  const double cell_volume = h * h * h;
  std::vector<std::vector<std::int64_t>> cells(n);
  for (std::size_t c = 0; c < lattice.label.size(); ++c) {
    const std::uint16_t l = lattice.label[c];
    if (l != 0 && l != bone) cells[l - 1].push_back(static_cast<std::int64_t>(c));
  }
  std::vector<std::int64_t> deficit(n, 0);
  for (std::size_t m = 0; m < n; ++m) {
    const auto target = static_cast<std::int64_t>(std::llround(muscles[m].volume / cell_volume));
    deficit[m] = std::max<std::int64_t>(0, target - static_cast<std::int64_t>(cells[m].size()));
  }
  const Eigen::Array3i size = lattice.cells;
  const std::int64_t sx = size.x();
  const std::int64_t sxy = sx * size.y();
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t m = 0; m < n; ++m) {
      if (deficit[m] == 0) continue;
      std::vector<std::int64_t> frontier;
      for (const std::int64_t c : cells[m]) {
        const std::int64_t i = c % sx;
        const std::int64_t j = (c / sx) % size.y();
        const std::int64_t k = c / sxy;
        const std::array<std::pair<bool, std::int64_t>, 6> next = {{
            {i > 0, c - 1},
            {i + 1 < sx, c + 1},
            {j > 0, c - sx},
            {j + 1 < size.y(), c + sx},
            {k > 0, c - sxy},
            {k + 1 < size.z(), c + sxy},
        }};
        for (const auto& [inside_grid, d] : next) {
          if (inside_grid && lattice.label[static_cast<std::size_t>(d)] == 0) frontier.push_back(d);
        }
      }
      std::ranges::sort(frontier);
      frontier.erase(std::unique(frontier.begin(), frontier.end()), frontier.end());
      if (frontier.empty()) continue;
      std::vector<std::pair<double, std::int64_t>> ranked(frontier.size());
      parallel_for(frontier.size(), options.threads, [&](std::size_t f) {
        const std::int64_t c = frontier[f];
        const Eigen::Vector3d x =
            lattice.centre(static_cast<int>(c % sx), static_cast<int>((c / sx) % size.y()),
                           static_cast<int>(c / sxy));
        ranked[f] = {std::sqrt(muscles[m].tree->closest_point(x).squared_distance), c};
      });
      std::ranges::sort(ranked);
      const auto take = static_cast<std::size_t>(
          std::min<std::int64_t>(deficit[m], static_cast<std::int64_t>(ranked.size())));
      for (std::size_t t = 0; t < take; ++t) {
        lattice.label[static_cast<std::size_t>(ranked[t].second)] =
            static_cast<std::uint16_t>(m + 1);
        cells[m].push_back(ranked[t].second);
        out[m].depth_mm = std::max(out[m].depth_mm, ranked[t].first);
      }
      deficit[m] -= static_cast<std::int64_t>(take);
      out[m].cells += static_cast<std::int64_t>(take);
    }
  }
  return out;
}

}  // namespace

LabelledLattice build_labelled_lattice(const std::vector<NamedSurface>& muscles,
                                       const std::vector<NamedSurface>& bones,
                                       const LatticeOptions& options) {
  if (!(options.spacing_mm > 0) || !std::isfinite(options.spacing_mm)) {
    throw InvalidInputError("lattice spacing_mm must be a positive number of mm, got " +
                            std::to_string(options.spacing_mm));
  }
  if (options.padding_cells < 1) {
    throw InvalidInputError("lattice padding_cells must be at least 1, got " +
                            std::to_string(options.padding_cells));
  }
  if (!(options.max_regrowth_mm >= 0) || !std::isfinite(options.max_regrowth_mm)) {
    throw InvalidInputError("lattice max_regrowth_mm must be a non-negative number of mm, got " +
                            std::to_string(options.max_regrowth_mm));
  }
  if (muscles.empty()) throw InvalidInputError("lattice: no muscles to fill");
  if (muscles.size() > kMaxMuscles) {
    throw InvalidInputError("lattice: " + std::to_string(muscles.size()) + " muscles, at most " +
                            std::to_string(kMaxMuscles));
  }
  std::vector<Body> muscle_bodies;
  muscle_bodies.reserve(muscles.size());
  for (const NamedSurface& m : muscles) muscle_bodies.push_back(prepare(m, "muscle"));
  std::vector<Body> bone_bodies;
  bone_bodies.reserve(bones.size());
  for (const NamedSurface& b : bones) bone_bodies.push_back(prepare(b, "bone"));

  LabelledLattice lattice;
  lattice.spacing_mm = options.spacing_mm;
  Eigen::AlignedBox3d all;
  for (const Body& body : muscle_bodies) all.extend(body.box);
  const double pad = options.padding_cells * options.spacing_mm;
  lattice.origin = all.min() - Vector3d::Constant(pad);
  const Eigen::Array3d per_axis = ((all.sizes().array() + 2.0 * pad) / options.spacing_mm).ceil();
  if (per_axis.prod() > static_cast<double>(options.max_cells)) {
    throw InvalidInputError("lattice: the muscles' box needs more than " +
                            std::to_string(options.max_cells) + " cells at spacing_mm " +
                            std::to_string(options.spacing_mm) + " (choose a larger spacing)");
  }
  lattice.cells = per_axis.cast<int>();
  lattice.label.assign(static_cast<std::size_t>(per_axis.prod()), 0);
  const double cell_volume = std::pow(options.spacing_mm, 3);

  // Bones first: their cells are no muscle's.
  for (const Body& bone : bone_bodies) {
    const CellRange r = cells_of(bone.box, lattice);
    const int columns = (r.hi.x() - r.lo.x() + 1) * (r.hi.y() - r.lo.y() + 1);
    if (columns <= 0 || r.hi.z() < r.lo.z()) continue;
    parallel_for(static_cast<std::size_t>(columns), options.threads, [&](std::size_t c) {
      const int width = r.hi.x() - r.lo.x() + 1;
      const int i = r.lo.x() + static_cast<int>(c) % width;
      const int j = r.lo.y() + static_cast<int>(c) / width;
      fill_column(bone, lattice, i, j, r.lo.z(), r.hi.z(), [&](int k) {
        lattice.label[static_cast<std::size_t>(lattice.index(i, j, k))] = kBone;
      });
    });
  }

  // Then the muscles in order; a contested cell goes to the muscle it lies
  // deepest in. The depth of a cell in its current owner is computed when
  // first contested (NaN until then).
  std::vector<float> depth(lattice.label.size(), std::numeric_limits<float>::quiet_NaN());
  const std::size_t n = muscle_bodies.size();
  std::vector<std::atomic<std::int64_t>> inside(n);  // value-initialised: 0
  std::vector<std::atomic<std::int64_t>> in_bone(n);
  std::vector<std::atomic<std::int64_t>> lost(n);
  for (std::size_t m = 0; m < n; ++m) {
    const Body& muscle = muscle_bodies[m];
    const auto own = static_cast<std::uint16_t>(m + 1);
    const CellRange r = cells_of(muscle.box, lattice);
    const int width = r.hi.x() - r.lo.x() + 1;
    const int columns = width * (r.hi.y() - r.lo.y() + 1);
    parallel_for(static_cast<std::size_t>(columns), options.threads, [&](std::size_t c) {
      const int i = r.lo.x() + static_cast<int>(c) % width;
      const int j = r.lo.y() + static_cast<int>(c) / width;
      fill_column(muscle, lattice, i, j, r.lo.z(), r.hi.z(), [&](int k) {
        ++inside[m];
        const auto cell = static_cast<std::size_t>(lattice.index(i, j, k));
        std::uint16_t& owner = lattice.label[cell];
        if (owner == kBone) {
          ++in_bone[m];
          return;
        }
        if (owner == 0) {
          owner = own;
          return;
        }
        const Vector3d x = lattice.centre(i, j, k);
        if (std::isnan(depth[cell])) {
          depth[cell] = static_cast<float>(
              std::sqrt(muscle_bodies[owner - 1].tree->closest_point(x).squared_distance));
        }
        const auto mine =
            static_cast<float>(std::sqrt(muscle.tree->closest_point(x).squared_distance));
        if (mine > depth[cell]) {
          ++lost[owner - 1];
          owner = own;
          depth[cell] = mine;
        } else {
          ++lost[m];
        }
      });
    });
  }
  const std::vector<Regrowth> regrowth = regrow(lattice, muscle_bodies, options, kBone);
  std::vector<std::int64_t> kept(n, 0);
  for (std::uint16_t& l : lattice.label) {
    if (l == kBone) {
      l = 0;
    } else if (l != 0) {
      ++kept[l - 1];
    }
  }
  lattice.muscles.resize(n);
  for (std::size_t m = 0; m < n; ++m) {
    MuscleCells& cells = lattice.muscles[m];
    cells.name = muscle_bodies[m].name;
    cells.segmented_mm3 = muscle_bodies[m].volume;
    cells.inside_mm3 = static_cast<double>(inside[m]) * cell_volume;
    cells.to_bones_mm3 = static_cast<double>(in_bone[m]) * cell_volume;
    cells.to_muscles_mm3 = static_cast<double>(lost[m]) * cell_volume;
    cells.regrown_mm3 = static_cast<double>(regrowth[m].cells) * cell_volume;
    cells.regrowth_depth_mm = regrowth[m].depth_mm;
    cells.kept_mm3 = static_cast<double>(kept[m]) * cell_volume;
  }
  return lattice;
}

}  // namespace mmm::volumetric
