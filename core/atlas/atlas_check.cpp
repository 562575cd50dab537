#include "core/atlas/atlas_check.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <sstream>

#include "core/atlas/atlas_io.h"
#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/penetration.h"
#include "core/mesh/signed_distance.h"

namespace mmm::atlas {
namespace {

// The fibre part of a path is never taken as less than this share of it
// (a tendon slack length above the path length, possible at rest, would
// otherwise make any line pass). Plantaris has the longest tendon of the leg
// for its path: a belly of 7-10 cm on a path of about 40 cm.
constexpr double kLeastFibrePart = 0.2;

std::string number_text(double value, int decimals) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(decimals);
  text << value;
  return text.str();
}

MeshHealth health_of(const std::string& element, const MeshLevel& level,
                     const mesh::IndexedMesh& surface) {
  const mesh::MeshCheckReport report = mesh::check_mesh(surface);
  MeshHealth health;
  health.element = element;
  health.level = level.level;
  health.faces = static_cast<int>(surface.num_faces());
  health.closed = report.closed();
  health.manifold = report.manifold();
  health.volume_mm3 = mesh::signed_volume(surface);
  health.oriented = report.orientation_consistent() && health.volume_mm3 > 0;
  return health;
}

void check_levels(const std::filesystem::path& dir, const std::string& element,
                  const std::vector<MeshLevel>& levels, AtlasCheckReport& report) {
  if (levels.empty()) report.problems.push_back(element + ": has no mesh");
  for (const MeshLevel& level : levels) {
    try {
      const MeshHealth health = health_of(element, level, load_mesh(dir, levels, level.level));
      if (!health.closed || !health.manifold || !health.oriented) {
        report.problems.push_back(element + " (" + level.level + ", " + level.file +
                                  "): not a closed, consistently outward-oriented 2-manifold");
      }
      report.meshes.push_back(health);
    } catch (const std::exception& e) {
      report.problems.push_back(element + " (" + level.level + "): " + e.what());
    }
  }
}

double rest_value(const Atlas& atlas, const std::string& coordinate) {
  for (const Joint& joint : atlas.joints) {
    for (const Coordinate& c : joint.coordinates) {
      if (c.name == coordinate) return c.rest_value;
    }
  }
  return 0.0;
}

}  // namespace

std::vector<Eigen::Vector3d> action_line_polyline(const Atlas& atlas, const ActionLine& line) {
  std::vector<Eigen::Vector3d> points;
  for (const PathPoint& point : line.points) {
    if (point.kind == PathPointKind::kConditional) {
      const double q = rest_value(atlas, point.coordinate);
      if (q < point.range[0] || q > point.range[1]) continue;
    }
    points.push_back(point.position);
  }
  return points;
}

double inside_fraction(const std::vector<Eigen::Vector3d>& polyline, double step_mm,
                       const std::function<bool(const Eigen::Vector3d&)>& inside) {
  if (polyline.empty()) return 0.0;
  if (step_mm <= 0) throw InvalidInputError("inside_fraction: step must be positive");
  int samples = 0;
  int inside_samples = 0;
  const auto sample = [&](const Eigen::Vector3d& p) {
    ++samples;
    if (inside(p)) ++inside_samples;
  };
  sample(polyline.front());
  for (std::size_t i = 1; i < polyline.size(); ++i) {
    const Eigen::Vector3d& a = polyline[i - 1];
    const Eigen::Vector3d& b = polyline[i];
    // Bounded, and defined for any segment: a non-finite or absurdly long one
    // (a corrupt action line) is sampled kMaxSegmentSamples times, not cast
    // out of int's range.
    constexpr double kMaxSegmentSamples = 1e5;
    const double wanted = std::ceil((b - a).norm() / step_mm);
    const int steps = std::isfinite(wanted)
                          ? static_cast<int>(std::clamp(wanted, 1.0, kMaxSegmentSamples))
                          : static_cast<int>(kMaxSegmentSamples);
    for (int k = 1; k <= steps; ++k) sample(a + (b - a) * (static_cast<double>(k) / steps));
  }
  return static_cast<double>(inside_samples) / samples;
}

AtlasCheckReport check_atlas(const std::filesystem::path& dir, const AtlasCheckOptions& options) {
  AtlasCheckReport report;
  Atlas atlas;
  try {
    atlas = read_atlas(dir);
  } catch (const std::exception& e) {
    report.problems.emplace_back(e.what());
    return report;
  }
  for (const std::string_view name : kRequiredLandmarks) {
    if (atlas.find_landmark(name) == nullptr) {
      report.problems.push_back("required landmark '" + std::string(name) + "' is missing");
    }
  }
  for (const Bone& bone : atlas.bones) check_levels(dir, bone.name, bone.meshes, report);
  for (const Muscle& muscle : atlas.muscles) check_levels(dir, muscle.name, muscle.meshes, report);
  for (const Structure& structure : atlas.structures) {
    check_levels(dir, structure.name, structure.meshes, report);
  }

  std::map<std::string, mesh::IndexedMesh> bone_surfaces;
  for (const Bone& bone : atlas.bones) {
    try {
      bone_surfaces[bone.name] = load_mesh(dir, bone.meshes);
    } catch (const std::exception&) {
      // Already reported by check_levels.
    }
  }
  std::map<std::string, mesh::IndexedMesh> structure_surfaces;
  for (const Structure& structure : atlas.structures) {
    try {
      structure_surfaces[structure.name] = load_mesh(dir, structure.meshes);
    } catch (const std::exception&) {
      // Already reported by check_levels.
    }
  }
  report.anatomy =
      check_anatomy(atlas, bone_surfaces, structure_surfaces, options.anatomy, report.problems);
  // Bones' signed distances, built once.
  std::map<std::string, std::unique_ptr<mesh::SignedDistance>> bones;
  for (const auto& [name, surface] : bone_surfaces) {
    bones[name] = std::make_unique<mesh::SignedDistance>(surface);
  }
  for (const Muscle& muscle : atlas.muscles) {
    MuscleCheck check;
    check.name = muscle.name;
    mesh::IndexedMesh surface;
    try {
      surface = load_mesh(dir, muscle.meshes);
    } catch (const std::exception&) {
      continue;  // reported by check_levels
    }
    check.volume_mm3 = mesh::signed_volume(surface);
    check.faces = static_cast<int>(surface.num_faces());
    for (const auto& [bone, distance] : bones) {
      const mesh::PenetrationReport penetration = mesh::penetration(surface, *distance);
      if (penetration.max_depth > check.max_penetration_mm) {
        check.max_penetration_mm = penetration.max_depth;
        check.deepest_bone = bone;
      }
    }
    if (check.max_penetration_mm > options.max_penetration_mm) {
      report.problems.push_back(muscle.name + " enters " + check.deepest_bone + " by " +
                                number_text(check.max_penetration_mm, 2) + " mm (at most " +
                                number_text(options.max_penetration_mm, 2) + " mm allowed)");
    }
    const mesh::SignedDistance muscle_distance(surface);
    const auto inside = [&](const Eigen::Vector3d& p) {
      return muscle_distance.winding().at(p) > 0.5;
    };
    for (const ActionLine& line : muscle.action_lines) {
      const std::vector<Eigen::Vector3d> polyline = action_line_polyline(atlas, line);
      ActionLineCheck line_check;
      line_check.muscle = muscle.name;
      line_check.line = line.name;
      for (std::size_t i = 1; i < polyline.size(); ++i) {
        line_check.length_mm += (polyline[i] - polyline[i - 1]).norm();
      }
      line_check.inside_fraction = inside_fraction(polyline, options.sample_step_mm, inside);
      // The tendon is not part of a muscle surface: what must lie inside is
      // the fibre part of the path, its length less the tendon's.
      line_check.tendon_mm = std::clamp(muscle.tendon_slack_length_mm, 0.0,
                                        (1.0 - kLeastFibrePart) * line_check.length_mm);
      const double fibre_part = line_check.length_mm - line_check.tendon_mm;
      line_check.fibre_part_inside_fraction =
          fibre_part > 0
              ? std::min(1.0, line_check.inside_fraction * line_check.length_mm / fibre_part)
              : line_check.inside_fraction;
      check.min_inside_fraction =
          std::min(check.min_inside_fraction, line_check.fibre_part_inside_fraction);
      check.min_line_inside_fraction =
          std::min(check.min_line_inside_fraction, line_check.inside_fraction);
      if (line_check.fibre_part_inside_fraction < options.min_inside_fraction) {
        report.problems.push_back(muscle.name + ": action line " + line.name + " has " +
                                  number_text(100 * line_check.fibre_part_inside_fraction, 1) +
                                  "% of its fibre part inside the muscle (" +
                                  number_text(100 * line_check.inside_fraction, 1) + "% of its " +
                                  number_text(line_check.length_mm, 0) + " mm, tendon " +
                                  number_text(line_check.tendon_mm, 0) + " mm; at least " +
                                  number_text(100 * options.min_inside_fraction, 0) +
                                  "% required)");
      }
      report.action_lines.push_back(line_check);
    }
    report.muscles.push_back(check);
  }
  return report;
}

}  // namespace mmm::atlas
