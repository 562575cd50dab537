#include "core/motion/motion_points.h"

#include <iomanip>
#include <sstream>

#include "core/errors.h"

namespace mmm::motion {
namespace {

int body_of(const Skeleton& skeleton, const std::string& bone, const std::string& what) {
  const std::optional<int> index = skeleton.body_index(bone);
  if (!index) {
    throw InvalidInputError(what + " is on bone '" + bone +
                            "', which the motion's skeleton does not have");
  }
  return *index;
}

InvalidInputError unknown_coordinate(const std::string& what, const std::string& coordinate) {
  return InvalidInputError{what + ": coordinate '" + coordinate +
                           "' is not one of the motion's coordinates"};
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

// How a point's position follows the frame.
struct Rule {
  int body = 0;
  Eigen::Vector3d local = Eigen::Vector3d::Zero();  // fixed points (body coordinates)
  const atlas::PathPoint* point = nullptr;          // conditional / moving
  Eigen::Isometry3d bone_frame = Eigen::Isometry3d::Identity();
  std::array<int, 3> moving{-1, -1, -1};
  int condition = -1;
};

}  // namespace

PointTrajectories atlas_point_trajectories(const atlas::Atlas& atlas, const Skeleton& skeleton,
                                           const FusedMotion& motion) {
  PointTrajectories result;
  std::vector<Rule> rules;
  const auto add = [&](TrackedPoint point, const Rule& rule) {
    result.points.push_back(std::move(point));
    rules.push_back(rule);
  };
  for (const atlas::Landmark& landmark : atlas.landmarks) {
    add({"landmark", landmark.name, landmark.name, landmark.bone},
        {body_of(skeleton, landmark.bone, "landmark " + landmark.name), landmark.position});
  }
  for (const atlas::Muscle& muscle : atlas.muscles) {
    const auto areas = [&](const std::vector<atlas::AttachmentArea>& list, const char* kind) {
      for (std::size_t i = 0; i < list.size(); ++i) {
        add({kind, muscle.name, std::to_string(i), list[i].bone},
            {body_of(skeleton, list[i].bone, "muscle " + muscle.name + " " + kind),
             list[i].centroid});
      }
    };
    areas(muscle.origins, "origin");
    areas(muscle.insertions, "insertion");
    for (const atlas::ActionLine& line : muscle.action_lines) {
      for (const atlas::PathPoint& point : line.points) {
        const std::string what = "action line " + line.name + " point " + point.name;
        Rule rule{body_of(skeleton, point.bone, what), point.position};
        if (point.kind != atlas::PathPointKind::kFixed) {
          rule.point = &point;
          rule.bone_frame = atlas.find_bone(point.bone) != nullptr
                                ? atlas.find_bone(point.bone)->frame
                                : Eigen::Isometry3d::Identity();
        }
        if (point.kind == atlas::PathPointKind::kConditional) {
          const std::optional<int> c = motion.coordinate_index(point.coordinate);
          if (!c) throw unknown_coordinate(what, point.coordinate);
          rule.condition = *c;
        }
        if (point.kind == atlas::PathPointKind::kMoving) {
          for (int k = 0; k < 3; ++k) {
            const std::string& name = point.moving_coordinates[static_cast<std::size_t>(k)];
            if (name.empty()) continue;
            const std::optional<int> c = motion.coordinate_index(name);
            if (!c) throw unknown_coordinate(what, name);
            rule.moving[static_cast<std::size_t>(k)] = *c;
          }
        }
        add({"path_point", muscle.name + "/" + line.name, point.name, point.bone}, rule);
      }
    }
  }
  for (const atlas::Marker& marker : atlas.markers) {
    add({"marker", marker.name, marker.name, marker.bone},
        {body_of(skeleton, marker.bone, "marker " + marker.name), marker.position});
  }
  const Eigen::Index frames = motion.num_frames();
  const auto count = static_cast<Eigen::Index>(rules.size());
  result.positions.resize(frames, 3 * count);
  result.active = Eigen::MatrixXi::Ones(frames, count);
  for (Eigen::Index k = 0; k < frames; ++k) {
    const std::vector<Eigen::Isometry3d>& poses = motion.poses[static_cast<std::size_t>(k)];
    for (Eigen::Index i = 0; i < count; ++i) {
      const Rule& rule = rules[static_cast<std::size_t>(i)];
      Eigen::Vector3d local = rule.local;
      if (rule.point != nullptr && rule.point->kind == atlas::PathPointKind::kMoving) {
        Eigen::Vector3d in_bone;
        for (int a = 0; a < 3; ++a) {
          const int c = rule.moving[static_cast<std::size_t>(a)];
          const double q = c < 0 ? 0.0 : motion.coordinates(k, c);
          in_bone(a) = rule.point->moving_functions[static_cast<std::size_t>(a)].evaluate(q);
        }
        local = rule.bone_frame * in_bone;
      }
      if (rule.condition >= 0) {
        const double q = motion.coordinates(k, rule.condition);
        result.active(k, i) = q >= rule.point->range[0] && q <= rule.point->range[1] ? 1 : 0;
      }
      result.positions.block<1, 3>(k, 3 * i) =
          (poses[static_cast<std::size_t>(rule.body)] * local).transpose();
    }
  }
  return result;
}

PointTrajectories marker_trajectories(const Skeleton& skeleton, const FusedMotion& motion) {
  PointTrajectories result;
  for (const SkeletonMarker& marker : skeleton.markers) {
    result.points.push_back({"marker", marker.name, marker.name,
                             skeleton.bodies[static_cast<std::size_t>(marker.body)].name});
  }
  const Eigen::Index frames = motion.num_frames();
  const auto count = static_cast<Eigen::Index>(skeleton.markers.size());
  result.positions.resize(frames, 3 * count);
  result.active = Eigen::MatrixXi::Ones(frames, count);
  for (Eigen::Index k = 0; k < frames; ++k) {
    for (Eigen::Index i = 0; i < count; ++i) {
      const SkeletonMarker& marker = skeleton.markers[static_cast<std::size_t>(i)];
      result.positions.block<1, 3>(k, 3 * i) =
          (motion.poses[static_cast<std::size_t>(k)][static_cast<std::size_t>(marker.body)] *
           marker.local)
              .transpose();
    }
  }
  return result;
}

std::string point_trajectories_csv(const PointTrajectories& points, const FusedMotion& motion) {
  std::ostringstream csv;
  csv << "frame,time_s,kind,element,name,bone,x_mm,y_mm,z_mm,active\n";
  csv << std::setprecision(10);
  for (Eigen::Index k = 0; k < points.positions.rows(); ++k) {
    const int frame = k < static_cast<Eigen::Index>(motion.trial_frames.size())
                          ? motion.trial_frames[static_cast<std::size_t>(k)] + 1
                          : static_cast<int>(k) + 1;
    for (std::size_t i = 0; i < points.points.size(); ++i) {
      const TrackedPoint& p = points.points[i];
      const auto column = 3 * static_cast<Eigen::Index>(i);
      csv << frame << ',' << motion.times(k) << ',' << p.kind << ',' << csv_field(p.element) << ','
          << csv_field(p.name) << ',' << csv_field(p.bone) << ',' << points.positions(k, column)
          << ',' << points.positions(k, column + 1) << ',' << points.positions(k, column + 2) << ','
          << points.active(k, static_cast<Eigen::Index>(i)) << '\n';
    }
  }
  return csv.str();
}

StickFigure stick_figure(const Skeleton& skeleton, const std::vector<Eigen::Isometry3d>& poses) {
  StickFigure figure;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t b = 0; b < skeleton.bodies.size(); ++b) {
    const SkeletonBody& body = skeleton.bodies[b];
    if (body.parent < 0 || body.axes.empty()) continue;
    const auto centre = [&](std::size_t index) {
      return Eigen::Vector3d(poses[index] * skeleton.bodies[index].child_offset.translation());
    };
    // The nearest moving ancestor's joint centre (welded bodies skipped).
    auto parent = static_cast<std::size_t>(body.parent);
    while (skeleton.bodies[parent].axes.empty() && skeleton.bodies[parent].parent >= 0) {
      parent = static_cast<std::size_t>(skeleton.bodies[parent].parent);
    }
    const auto first = static_cast<int>(points.size());
    points.push_back(centre(parent));
    points.push_back(centre(b));
    figure.segments.push_back({first, first + 1});
  }
  figure.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    figure.points.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  }
  return figure;
}

}  // namespace mmm::motion
