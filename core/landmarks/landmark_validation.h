#pragma once
// Checks an operator's landmark submission on a calibrated biplanar pair
// before it is accepted: every problem is listed (never only the first), one
// sentence each naming the landmark and the view, and the landmarks that
// could be triangulated are returned with their reprojection errors.
//
//   for each submitted name:   known? (else "did you mean")
//   for each known landmark:   given in every view? pixel finite, inside the image?
//                              triangulate (triangulation.h) from its finite pixels
//                              when there are >= 2; reprojection error per view
//                              <= tolerance?
//   required names present?
//   on the triangulated points: heights in the expected order (z), distances
//   between pairs in their anatomical ranges, on the expected side of the
//   sagittal midline
//
// The anatomical checks catch the errors an operator makes that geometry alone
// cannot see: a landmark of the other leg, two landmarks swapped, the patella
// clicked where the femoral head was meant.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/image/projection.h"
#include "core/landmarks/landmark_set.h"
#include "core/landmarks/triangulation.h"

namespace mmm::landmarks {

// What the operator submitted: landmark name -> view name -> pixel (u, v)
// (core/image/projection.h conventions: the image spans [0, width] x [0, height]).
using PixelSubmission = std::map<std::string, std::map<std::string, Eigen::Vector2d>>;

// The distance between two landmarks must lie in [min_mm, max_mm].
struct DistanceRange {
  std::string from;
  std::string to;
  double min_mm = 0;
  double max_mm = 0;
};

struct ValidationRules {
  // Landmarks that must be submitted.
  std::vector<std::string> required = {"femoral_head_centre_r", "patella_centre_r"};
  // Landmarks that may be submitted. Any other name is reported as unknown.
  std::vector<std::string> optional = {"ankle_centre_r"};

  // Largest accepted reprojection error in any view (mm at the isocentre).
  // 3 mm: an operator placing a centre (femoral head, patella, ankle) by eye
  // scatters by about 1-1.5 mm (several pixels at EOS-like 0.2-0.4 mm
  // spacing), so twice that passes careful work, while picking a different
  // point in one view (the patella's apex instead of its centre, the top of
  // the talar dome instead of the ankle centre: 10 mm or more) fails. In a
  // frontal + lateral pair only the heights (v) are seen twice, so a vertical
  // disagreement of d mm between the views shows as about d/2 in each.
  double reprojection_tolerance_mm = 3.0;

  // The leg the landmarks belong to: "right" or "left". Every triangulated
  // landmark must lie on that side of the sagittal midline by side_margin_mm.
  std::string side = "right";
  // x of the sagittal midline (mm, patient frame). Default (nullopt): the x
  // of the point where the views' central rays (through each image centre)
  // cross, i.e. the isocentre of the system (make_biplanar_views: the
  // isocentre x). The operator centres the patient in the field, and the
  // synthetic patients of core/atlas/synthetic_patient.h centre the field on
  // both hip bones and the right leg: there the isocentre lies ~8 mm to the
  // right of the midline. Set it when the field is centred on one leg.
  std::optional<double> midline_x_mm;
  // 10 mm: the joint centres of a leg lie 40-100 mm from the midline in a
  // standing adult (hip ~ 80-100, knee ~ 60-100, ankle ~ 40-100 mm with the
  // feet a little apart), so a 10 mm margin still accepts them with an
  // isocentre ~10 mm off the midline toward that leg, while the other leg's
  // landmarks (mirror images, 40 mm or more to the other side) fail.
  double side_margin_mm = 10.0;
  // Landmarks that belong to the other side of the midline (for a right leg,
  // the left ASIS when the pelvis's landmarks are asked for).
  std::vector<std::string> opposite_side;

  // Landmarks in order from superior to inferior: each present landmark must
  // be higher (larger z) than the next present one.
  std::vector<std::string> top_to_bottom = {"femoral_head_centre_r", "patella_centre_r",
                                            "ankle_centre_r"};

  // Anatomical distance ranges for adults, with margins. Basis: segment
  // lengths as fractions of stature H (Winter, "Biomechanics and Motor
  // Control of Human Movement", 4th ed. 2009, table 4.1: thigh 0.245 H,
  // leg 0.246 H), adult statures 1.40-2.10 m, hence 340-520 mm for either
  // segment. The patella centre lies 20-60 mm above the knee joint line in
  // extension, which makes hip-patella 280-500 mm and patella-ankle
  // 360-580 mm; widened by 30-90 mm at each end for anatomical variation:
  //   femoral head centre - patella centre: 250-550 mm
  //   patella centre - ankle centre:        270-620 mm
  // Checks: the Visible Human Female (data README) has 371 mm from femoral
  // head to patella; a synthetic patient of the VHF atlas (seed 1) 343 mm and
  // 382 mm; gait2392 scaled to subject01 (1.80 m) has a 454 mm femur.
  std::vector<DistanceRange> distances = {
      {"femoral_head_centre_r", "patella_centre_r", 250.0, 550.0},
      {"patella_centre_r", "ankle_centre_r", 270.0, 620.0}};

  // The solver settings for every landmark.
  TriangulationOptions triangulation;
};

struct ValidationResult {
  // One sentence per problem found, in the order of the checks above; empty
  // when the submission is accepted.
  std::vector<std::string> reasons;
  // Every known landmark given with finite pixels in >= 2 views, triangulated
  // (frame "patient", source "radiographs", pixels and reprojection errors
  // per view), in the order required then optional; nullopt when none could be.
  std::optional<LandmarkSet> landmarks;
  double midline_x_mm = 0;  // the midline used (mm)

  [[nodiscard]] bool accepted() const { return reasons.empty(); }
};

// x (mm) of the point nearest to the views' central rays (through each image
// centre (width/2, height/2)) in the least-squares sense of
// image::triangulate_linear. Throws InvalidInputError when the views are
// fewer than 2, invalid, or their central rays are parallel.
double central_ray_crossing_x(std::span<const image::RadiographView> views);

// Checks `submission` against `rules` (see the file comment). Problems with
// the submission are reasons, never exceptions. Throws InvalidInputError only
// for bad views (fewer than 2, an invalid one, repeated names) or bad rules
// (side not "right"/"left", a non-finite or negative tolerance or margin, a
// range with min > max, a name both required and optional).
ValidationResult validate_submission(std::span<const image::RadiographView> views,
                                     const PixelSubmission& submission,
                                     const ValidationRules& rules = {});

// The anatomical checks of 3-D landmarks that did not come from the station
// (a Slicer import, a static trial): the same heights, distances and sides as
// validate_submission, plus the front-to-back and left-to-right order of
// pairs, which a mirrored file breaks. x toward the subject's right, y
// anterior, z superior (RAS), mm. Only landmarks present are checked.
struct AnatomyRules {
  // Each chain superior to inferior: every present landmark higher (z) than
  // the next present one.
  std::vector<std::vector<std::string>> top_to_bottom = {
      {"asis_r", "femoral_head_centre_r", "patella_centre_r", "ankle_centre_r"},
      {"asis_l", "femoral_head_centre_r"},
      {"femoral_head_centre_r", "knee_centre_r", "ankle_centre_r"}};
  // (anterior, posterior): the first lies in front (larger y). In the VHF
  // atlas the margins are 42-140 mm (patella - femoral head: 27 mm), far
  // beyond what posture or anatomy changes; all of them flip in a file whose
  // x and y are negated.
  std::vector<std::pair<std::string, std::string>> anterior_posterior = {
      {"asis_r", "sacral_point"},
      {"asis_l", "sacral_point"},
      {"asis_r", "femoral_head_centre_r"},
      {"patella_centre_r", "knee_centre_r"},
      {"patella_centre_r", "femoral_head_centre_r"},
      {"patella_centre_r", "ankle_centre_r"},
      {"ankle_centre_r", "heel_r"}};
  // (lateral, medial) on the leg's side: the first lies farther out.
  std::vector<std::pair<std::string, std::string>> lateral_medial = {
      {"lateral_epicondyle_r", "medial_epicondyle_r"},
      {"lateral_malleolus_r", "medial_malleolus_r"}};
  // (right, left): the first lies to the subject's right (larger x).
  std::vector<std::pair<std::string, std::string>> right_left = {{"asis_r", "asis_l"}};
  // The leg ("right" or "left"); its landmarks (every present one except
  // the midline and opposite-side ones below) must lie on its side of the
  // midline by side_margin_mm. The midline is the x of the sacral point, else
  // of the middle of the two ASIS; without them the side is not checked.
  std::string side = "right";
  double side_margin_mm = 10.0;  // as ValidationRules::side_margin_mm
  std::vector<std::string> midline = {"sacral_point"};
  std::vector<std::string> opposite_side = {"asis_l"};
  // As ValidationRules::distances, with the ASIS span (160-340 mm: adult
  // inter-ASIS distances are 200-290 mm, widened for obesity and children).
  std::vector<DistanceRange> distances = {
      {"femoral_head_centre_r", "patella_centre_r", 250.0, 550.0},
      {"patella_centre_r", "ankle_centre_r", 270.0, 620.0},
      {"asis_r", "asis_l", 160.0, 340.0}};
  // The coordinate system the file declared, named in the hint for mirrored points.
  std::string declared_coordinate_system = "RAS";
};

// One sentence per problem found (empty: the set passes). When order checks
// fail and every one of them would pass with x and y negated, the last
// sentence says the points look mirrored and names the coordinate system
// that would fix it ("the points look like LPS coordinates read as RAS ...;
// set the point list's coordinateSystem to \"LPS\""). Throws
// InvalidInputError for bad rules (side not "right"/"left").
std::vector<std::string> check_landmark_anatomy(const LandmarkSet& set,
                                                const AnatomyRules& rules = {});

}  // namespace mmm::landmarks
