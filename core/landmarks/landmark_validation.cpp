#include "core/landmarks/landmark_validation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <string_view>

#include "core/errors.h"
#include "core/landmarks/message_text.h"
#include "core/suggest.h"

namespace mmm::landmarks {

namespace {

// "4.6" (one decimal: messages for people, not data).
std::string mm(double value) {
  std::array<char, 32> buffer{};
  std::snprintf(buffer.data(), buffer.size(), "%.1f", value);
  return buffer.data();
}

using detail::concat;

std::string pixel_text(const Eigen::Vector2d& pixel) {
  return "(" + mm(pixel.x()) + ", " + mm(pixel.y()) + ")";
}

void check_rules(const ValidationRules& rules) {
  if (rules.side != "right" && rules.side != "left") {
    throw InvalidInputError(R"(ValidationRules.side must be "right" or "left", got ")" +
                            rules.side + "\"");
  }
  const auto finite_non_negative = [](double value, const char* field) {
    if (!std::isfinite(value) || value < 0) {
      throw InvalidInputError(std::string("ValidationRules.") + field +
                              " must be a finite number >= 0, got " + std::to_string(value));
    }
  };
  finite_non_negative(rules.reprojection_tolerance_mm, "reprojection_tolerance_mm");
  finite_non_negative(rules.side_margin_mm, "side_margin_mm");
  if (rules.midline_x_mm && !std::isfinite(*rules.midline_x_mm)) {
    throw InvalidInputError("ValidationRules.midline_x_mm must be finite when set");
  }
  for (const DistanceRange& range : rules.distances) {
    if (!std::isfinite(range.min_mm) || !std::isfinite(range.max_mm) || range.min_mm < 0 ||
        range.min_mm > range.max_mm) {
      throw InvalidInputError("ValidationRules.distances: range " + range.from + " - " + range.to +
                              " must have 0 <= min_mm <= max_mm, got [" +
                              std::to_string(range.min_mm) + ", " + std::to_string(range.max_mm) +
                              "]");
    }
  }
  for (const std::string& name : rules.required) {
    if (std::ranges::find(rules.optional, name) != rules.optional.end()) {
      throw InvalidInputError("ValidationRules: '" + name + "' is both required and optional");
    }
  }
}

void check_views(std::span<const image::RadiographView> views) {
  if (views.size() < 2) {
    throw InvalidInputError("validate_submission: need at least 2 views, got " +
                            std::to_string(views.size()));
  }
  std::set<std::string> names;
  for (const image::RadiographView& view : views) {
    image::validate_view(view);
    if (!names.insert(view.name).second) {
      throw InvalidInputError("validate_submission: view name '" + view.name + "' is used twice");
    }
  }
}

}  // namespace

double central_ray_crossing_x(std::span<const image::RadiographView> views) {
  std::vector<Eigen::Vector2d> centres;
  centres.reserve(views.size());
  for (const image::RadiographView& view : views) {
    centres.emplace_back(0.5 * view.width, 0.5 * view.height);
  }
  return image::triangulate_linear(views, centres).x();
}

ValidationResult validate_submission(std::span<const image::RadiographView> views,
                                     const PixelSubmission& submission,
                                     const ValidationRules& rules) {
  check_rules(rules);
  check_views(views);
  ValidationResult result;
  std::vector<std::string>& reasons = result.reasons;

  std::vector<std::string> known = rules.required;
  known.insert(known.end(), rules.optional.begin(), rules.optional.end());
  std::vector<std::string> view_names;
  for (const image::RadiographView& view : views) view_names.push_back(view.name);

  // Names: unknown landmarks, unknown views.
  for (const auto& [name, by_view] : submission) {
    if (std::ranges::find(known, name) == known.end()) {
      reasons.push_back("Landmark '" + name + "' is not one this task asks for" +
                        did_you_mean(name, known) + " (expected: " + join_names(known) + ").");
      continue;
    }
    for (const auto& [view, pixel] : by_view) {
      if (std::ranges::find(view_names, view) == view_names.end()) {
        reasons.push_back(concat(
            {"Landmark '", name, "' is given in view '", view, "', which this study does not have",
             did_you_mean(view, view_names), " (views: ", join_names(view_names), ")."}));
      }
    }
  }
  for (const std::string& name : rules.required) {
    if (!submission.contains(name)) {
      reasons.push_back("Required landmark '" + name + "' is missing.");
    }
  }

  // Per landmark and view: present, finite, inside; then triangulation.
  LandmarkSet triangulated;
  triangulated.frame = "patient";
  triangulated.source = "radiographs";
  for (const std::string& name : known) {
    const auto entry = submission.find(name);
    if (entry == submission.end()) continue;
    std::vector<image::RadiographView> used_views;
    std::vector<Eigen::Vector2d> used_pixels;
    for (const image::RadiographView& view : views) {
      const auto given = entry->second.find(view.name);
      if (given == entry->second.end()) {
        reasons.push_back("Landmark '" + name + "' is missing in view '" + view.name + "'.");
        continue;
      }
      const Eigen::Vector2d& pixel = given->second;
      if (!pixel.allFinite()) {
        reasons.push_back("Landmark '" + name + "' in view '" + view.name +
                          "' has a pixel position that is not a finite number.");
        continue;
      }
      if (pixel.x() < 0 || pixel.x() > view.width || pixel.y() < 0 || pixel.y() > view.height) {
        reasons.push_back("Landmark '" + name + "' in view '" + view.name + "' is at pixel " +
                          pixel_text(pixel) + ", outside the image [0, " +
                          std::to_string(view.width) + "] x [0, " + std::to_string(view.height) +
                          "].");
      }
      // Still used: a finite pixel just off the image is geometry all the same.
      used_views.push_back(view);
      used_pixels.push_back(pixel);
    }
    if (used_views.size() < 2) continue;
    Triangulation solved;
    try {
      solved = triangulate(used_views, used_pixels, rules.triangulation);
    } catch (const std::exception& error) {
      reasons.push_back("Landmark '" + name + "' could not be triangulated: " + error.what());
      continue;
    }
    Landmark landmark;
    landmark.name = name;
    landmark.position_mm = solved.point_mm;
    for (std::size_t i = 0; i < used_views.size(); ++i) {
      const std::string& view = used_views[i].name;
      const double error = solved.reprojection_error_mm[i];
      landmark.pixels[view] = used_pixels[i];
      landmark.reprojection_error_mm[view] = error;
      if (error > rules.reprojection_tolerance_mm) {
        reasons.push_back(
            concat({"Landmark '", name, "' in view '", view, "': reprojection error ", mm(error),
                    " mm exceeds the tolerance of ", mm(rules.reprojection_tolerance_mm),
                    " mm; the views disagree on where it is (check its height in each view)."}));
      }
    }
    triangulated.landmarks.push_back(std::move(landmark));
  }

  // Anatomy, on the triangulated points.
  std::vector<const Landmark*> column;
  for (const std::string& name : rules.top_to_bottom) {
    if (const Landmark* landmark = triangulated.find(name)) column.push_back(landmark);
  }
  for (std::size_t i = 0; i + 1 < column.size(); ++i) {
    const Landmark& upper = *column[i];
    const Landmark& lower = *column[i + 1];
    if (!(upper.position_mm.z() > lower.position_mm.z())) {
      reasons.push_back("Landmark '" + upper.name + "' (z = " + mm(upper.position_mm.z()) +
                        " mm) should be above '" + lower.name +
                        "' (z = " + mm(lower.position_mm.z()) + " mm); were they swapped?");
    }
  }
  for (const DistanceRange& range : rules.distances) {
    const Landmark* from = triangulated.find(range.from);
    const Landmark* to = triangulated.find(range.to);
    if (from == nullptr || to == nullptr) continue;
    const double distance = (from->position_mm - to->position_mm).norm();
    if (distance < range.min_mm || distance > range.max_mm) {
      reasons.push_back("Distance from '" + range.from + "' to '" + range.to + "' is " +
                        mm(distance) + " mm, outside the adult range [" + mm(range.min_mm) + ", " +
                        mm(range.max_mm) + "] mm.");
    }
  }
  result.midline_x_mm = rules.midline_x_mm ? *rules.midline_x_mm : central_ray_crossing_x(views);
  const bool right = rules.side == "right";
  for (const Landmark& landmark : triangulated.landmarks) {
    // The pelvis's landmarks of the other side (the far ASIS) belong there.
    const bool other_side = std::find(rules.opposite_side.begin(), rules.opposite_side.end(),
                                      landmark.name) != rules.opposite_side.end();
    const bool expect_right = right != other_side;
    const std::string expected = expect_right ? "right" : "left";
    // Lateral distance toward the expected side (+x is the subject's right).
    const double lateral = expect_right ? landmark.position_mm.x() - result.midline_x_mm
                                        : result.midline_x_mm - landmark.position_mm.x();
    if (lateral < rules.side_margin_mm) {
      reasons.push_back(
          "Landmark '" + landmark.name + "' lies " + mm(std::abs(lateral)) +
          " mm to the subject's " + ((lateral >= 0) == expect_right ? "right" : "left") +
          " of the midline (x = " + mm(result.midline_x_mm) + " mm); " +
          (other_side ? "a landmark of the other side"
                      : "a landmark of the " + rules.side + " leg") +
          " must lie at least " + mm(rules.side_margin_mm) + " mm to the subject's " + expected +
          (other_side ? " (the two sides swapped?)." : " (the other leg clicked?)."));
    }
  }
  if (!triangulated.landmarks.empty()) result.landmarks = std::move(triangulated);
  return result;
}

std::vector<std::string> check_landmark_anatomy(const LandmarkSet& set, const AnatomyRules& rules) {
  if (rules.side != "right" && rules.side != "left") {
    throw InvalidInputError(R"(AnatomyRules.side must be "right" or "left", got ")" + rules.side +
                            "\"");
  }
  std::vector<std::string> reasons;
  const auto at = [&](const std::string& name) -> const Eigen::Vector3d* {
    const Landmark* landmark = set.find(name);
    return landmark == nullptr ? nullptr : &landmark->position_mm;
  };
  for (const std::vector<std::string>& chain : rules.top_to_bottom) {
    std::vector<std::string> present;
    for (const std::string& name : chain) {
      if (at(name) != nullptr) present.push_back(name);
    }
    for (std::size_t i = 0; i + 1 < present.size(); ++i) {
      const double upper = at(present[i])->z();
      const double lower = at(present[i + 1])->z();
      if (!(upper > lower)) {
        reasons.push_back("Landmark '" + present[i] + "' (z = " + mm(upper) +
                          " mm) should be above '" + present[i + 1] + "' (z = " + mm(lower) +
                          " mm); were they swapped, or is z not superior?");
      }
    }
  }
  for (const DistanceRange& range : rules.distances) {
    const Eigen::Vector3d* from = at(range.from);
    const Eigen::Vector3d* to = at(range.to);
    if (from == nullptr || to == nullptr) continue;
    const double distance = (*from - *to).norm();
    if (distance < range.min_mm || distance > range.max_mm) {
      reasons.push_back("Distance from '" + range.from + "' to '" + range.to + "' is " +
                        mm(distance) + " mm, outside the adult range [" + mm(range.min_mm) + ", " +
                        mm(range.max_mm) + "] mm (units wrong?).");
    }
  }
  // Order checks along x and y: counted, to tell a mirrored file from a
  // misplaced point.
  int order_checks = 0;
  int order_failures = 0;
  const auto order = [&](const std::string& first, const std::string& second, int axis, double sign,
                         const char* relation) {
    const Eigen::Vector3d* a = at(first);
    const Eigen::Vector3d* b = at(second);
    if (a == nullptr || b == nullptr) return;
    ++order_checks;
    if (sign * ((*a)(axis) - (*b)(axis)) > 0.0) return;
    ++order_failures;
    reasons.push_back("Landmark '" + first + "' should lie " + relation + " '" + second +
                      "', but it lies " + mm(std::abs((*a)(axis) - (*b)(axis))) + " mm " +
                      (axis == 1 ? "behind" : "on the other side of") + " it.");
  };
  for (const auto& [front, back] : rules.anterior_posterior) {
    order(front, back, 1, 1.0, "in front of (larger y than)");
  }
  const double outward = rules.side == "right" ? 1.0 : -1.0;
  for (const auto& [lateral, medial] : rules.lateral_medial) {
    order(lateral, medial, 0, outward, "lateral of");
  }
  for (const auto& [right, left] : rules.right_left) {
    order(right, left, 0, 1.0, "to the subject's right (larger x) of");
  }
  // Side of the midline.
  std::optional<double> midline;
  for (const std::string& name : rules.midline) {
    if (const Eigen::Vector3d* p = at(name)) midline = p->x();
  }
  if (!midline && !rules.right_left.empty()) {
    const Eigen::Vector3d* right = at(rules.right_left.front().first);
    const Eigen::Vector3d* left = at(rules.right_left.front().second);
    if (right != nullptr && left != nullptr) midline = 0.5 * (right->x() + left->x());
  }
  if (midline) {
    for (const Landmark& landmark : set.landmarks) {
      if (std::ranges::find(rules.midline, landmark.name) != rules.midline.end()) continue;
      const bool other =
          std::ranges::find(rules.opposite_side, landmark.name) != rules.opposite_side.end();
      const bool expect_right = (rules.side == "right") != other;
      ++order_checks;
      const double lateral =
          expect_right ? landmark.position_mm.x() - *midline : *midline - landmark.position_mm.x();
      if (lateral >= rules.side_margin_mm) continue;
      ++order_failures;
      reasons.push_back("Landmark '" + landmark.name + "' should lie at least " +
                        mm(rules.side_margin_mm) + " mm to the subject's " +
                        (expect_right ? "right" : "left") + " of the midline (x = " + mm(*midline) +
                        " mm), got " + mm(lateral) + " mm.");
    }
  }
  if (order_failures > 0 && order_failures == order_checks) {
    const bool declared_ras = rules.declared_coordinate_system == "RAS";
    const std::string really = declared_ras ? "LPS" : "RAS";
    reasons.push_back("Every front-back and left-right order is reversed: the points look like " +
                      really + " coordinates read as " + rules.declared_coordinate_system +
                      " (x and y negated; the model would come out turned by 180 degrees). "
                      "Hint: set the point list's coordinateSystem to \"" +
                      really + "\" (Slicer writes LPS), or export the points again.");
  }
  return reasons;
}

}  // namespace mmm::landmarks
