#include "core/image/drr.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "core/mesh/mass_properties.h"

namespace mmm::image {

namespace {

// A mesh ready for many rays: its tree, mu and padded bounding box.
struct PreparedMesh {
  const mesh::AabbTree* tree = nullptr;
  double mu = 0;
  Eigen::AlignedBox3d box;
};

std::vector<PreparedMesh> prepare(std::span<const AttenuatingMesh> meshes) {
  std::vector<PreparedMesh> prepared;
  prepared.reserve(meshes.size());
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const AttenuatingMesh& item = meshes[k];
    if (item.tree == nullptr) {
      throw InvalidInputError("attenuating mesh " + std::to_string(k) + " has no tree (null)");
    }
    if (!std::isfinite(item.mu_per_mm)) {
      throw InvalidInputError("attenuating mesh " + std::to_string(k) +
                              " has a non-finite mu_per_mm");
    }
    Eigen::AlignedBox3d box = item.tree->bounds();
    // The box touches the mesh's extreme vertices: pad it so that rounding in
    // the slab test never culls a ray that grazes one (1e-9 of the size).
    const double pad = 1e-9 * box.diagonal().norm() + 1e-12;
    box.min().array() -= pad;
    box.max().array() += pad;
    prepared.push_back({item.tree, item.mu_per_mm, box});
  }
  return prepared;
}

// Slab test: does origin + t direction, t >= 0, meet the box?
bool meets_box(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
               const Eigen::AlignedBox3d& box) {
  double t_enter = 0;
  double t_exit = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    const double o = origin(axis);
    const double d = direction(axis);
    if (d == 0) {
      if (o < box.min()(axis) || o > box.max()(axis)) return false;
      continue;
    }
    double t0 = (box.min()(axis) - o) / d;
    double t1 = (box.max()(axis) - o) / d;
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
    if (t_enter > t_exit) return false;
  }
  return true;
}

// Length (mm) of the unit-direction ray inside one closed mesh (see drr.h).
double length_inside(const PreparedMesh& item, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction) {
  if (!meets_box(origin, direction, item.box)) return 0;
  const std::vector<mesh::AabbTree::RayHit> hits = item.tree->all_hits(origin, direction);
  const mesh::IndexedMesh& surface = item.tree->mesh();
  int depth = 0;
  double opened = 0;
  double length = 0;
  for (const mesh::AabbTree::RayHit& hit : hits) {
    const Eigen::Vector3d a = surface.V.row(surface.F(hit.face, 0)).transpose();
    const Eigen::Vector3d b = surface.V.row(surface.F(hit.face, 1)).transpose();
    const Eigen::Vector3d c = surface.V.row(surface.F(hit.face, 2)).transpose();
    const bool entering = (b - a).cross(c - a).dot(direction) < 0;
    if (entering) {
      if (depth++ == 0) opened = hit.t;
    } else if (depth > 0 && --depth == 0) {
      length += hit.t - opened;
    }
  }
  return length;
}

double integrate(const std::vector<PreparedMesh>& meshes, const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& unit_direction) {
  double sum = 0;
  for (const PreparedMesh& item : meshes) {
    if (item.mu != 0) sum += item.mu * length_inside(item, origin, unit_direction);
  }
  return sum;
}

// Standard normal deviates from the raw output of a 64-bit Mersenne twister
// (Box-Muller, both values of each pair used): the standard distributions are
// implementation-defined, this is the same everywhere.
class NormalSource {
 public:
  explicit NormalSource(std::uint64_t seed) : engine_(seed) {}

  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    constexpr double kScale = 1.0 / 9007199254740992.0;  // 2^-53
    // u1 in (0, 1] (never 0, so the log is finite), u2 in [0, 1).
    const double u1 = static_cast<double>((engine_() >> 11U) + 1) * kScale;
    const double u2 = static_cast<double>(engine_() >> 11U) * kScale;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * std::numbers::pi * u2;
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

void check_option(double value, bool positive, const char* field) {
  if (!std::isfinite(value) || value < 0 || (positive && value == 0)) {
    throw InvalidInputError(std::string("RadiographOptions.") + field + " must be finite and " +
                            (positive ? "> 0" : ">= 0") + ", got " + std::to_string(value));
  }
}

}  // namespace

double line_integral(const Ray& ray, std::span<const AttenuatingMesh> meshes) {
  const double norm = ray.direction.norm();
  if (!ray.origin.allFinite() || !ray.direction.allFinite() || !(norm > 0)) {
    throw InvalidInputError(
        "line_integral: the ray needs a finite origin and a finite, non-zero "
        "direction");
  }
  return integrate(prepare(meshes), ray.origin, ray.direction / norm);
}

FloatImage render_drr(const RadiographView& view, std::span<const AttenuatingMesh> meshes,
                      const DrrOptions& options) {
  validate_view(view);
  if (options.threads < 1) {
    throw InvalidInputError("DrrOptions.threads must be >= 1, got " +
                            std::to_string(options.threads));
  }
  const std::vector<PreparedMesh> prepared = prepare(meshes);
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const double volume = mesh::signed_volume(meshes[k].tree->mesh());
    if (volume < 0) {
      throw InvalidInputError("attenuating mesh " + std::to_string(k) +
                              " encloses a negative volume (" + std::to_string(volume) +
                              " mm^3): it is inside out; reverse the order of its face corners");
    }
  }

  FloatImage image(view.width, view.height);
  std::atomic<int> next_row{0};
  const int workers = std::min(options.threads, view.height);
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(workers));
  const auto work = [&](int worker) {
    try {
      for (int row = next_row.fetch_add(1); row < view.height; row = next_row.fetch_add(1)) {
        for (int col = 0; col < view.width; ++col) {
          const Ray ray = backproject(view, {col + 0.5, row + 0.5});
          image.at(col, row) = static_cast<float>(integrate(prepared, ray.origin, ray.direction));
        }
      }
    } catch (...) {
      failures[static_cast<std::size_t>(worker)] = std::current_exception();
      next_row.store(view.height);  // the others stop after their current row
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  for (int worker = 1; worker < workers; ++worker) pool.emplace_back(work, worker);
  work(0);
  for (std::thread& thread : pool) thread.join();
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  return image;
}

GrayImage16 to_radiograph(const FloatImage& line_integrals, const RadiographOptions& options) {
  if (line_integrals.pixels.size() != line_integrals.sample_count()) {
    throw InvalidInputError("to_radiograph: image of " + std::to_string(line_integrals.width) +
                            " x " + std::to_string(line_integrals.height) + " holds " +
                            std::to_string(line_integrals.pixels.size()) + " samples");
  }
  if (!std::isfinite(options.photons_per_pixel) || !(options.photons_per_pixel > 1)) {
    throw InvalidInputError("RadiographOptions.photons_per_pixel must be finite and > 1, got " +
                            std::to_string(options.photons_per_pixel));
  }
  check_option(options.counts_per_attenuation, true, "counts_per_attenuation");
  check_option(options.offset_counts, false, "offset_counts");
  check_option(options.readout_noise_counts, false, "readout_noise_counts");

  GrayImage16 out(line_integrals.width, line_integrals.height);
  NormalSource normal(options.seed);
  const double n0 = options.photons_per_pixel;
  for (std::size_t i = 0; i < line_integrals.pixels.size(); ++i) {
    const double integral = line_integrals.pixels[i];
    if (!std::isfinite(integral)) {
      const auto width = static_cast<std::size_t>(line_integrals.width);
      throw InvalidInputError("to_radiograph: line integral at pixel (" +
                              std::to_string(i % width) + ", " + std::to_string(i / width) +
                              ") is not finite");
    }
    double attenuation = integral;
    if (options.quantum_noise) {
      const double expected = n0 * std::exp(-integral);
      const double counted = expected + std::sqrt(expected) * normal.next();
      attenuation = -std::log(std::max(counted, 1.0) / n0);
    }
    double value = options.offset_counts + options.counts_per_attenuation * attenuation;
    if (options.readout_noise_counts > 0) value += options.readout_noise_counts * normal.next();
    out.pixels[i] = static_cast<std::uint16_t>(std::clamp(std::round(value), 0.0, 65535.0));
  }
  return out;
}

}  // namespace mmm::image
