#pragma once
// Fitting generic action lines to a subject's muscle. The lines of a generic
// model (gait2392), mapped by bone registrations, keep their structure
// (points, kinds, bones) but rarely run through the subject's own muscle
// surface. A muscle's action line is the skeleton its surface is wrapped
// around (VPHOP D10.2, 3.4.2), so it has to lie inside:
//
//   1. the muscle's vertices are shared among its lines (each vertex goes
//      to the nearest line): one bundle per line;
//   2. each end (origin, insertion) moves onto the bone where its bundle
//      touches it (away from the articular surfaces `articular` names: a
//      gluteus minimus lies on the hip capsule over the femoral head but
//      inserts on the greater trochanter): the bone point nearest the centroid of the bundle
//      vertices within `contact_mm` of the bone and `search_radius_mm` of
//      the end, or, when the bundle does not touch the bone there, nearest
//      the bundle's closest approach to it (a tendon the surface leaves out);
//   3. each via point (fixed or conditional) moves to the centre of its
//      bundle's cross-section in the slab of half-width `slab_mm` across the
//      line at that point: the section's point deepest inside the muscle
//      among its centroid and midpoints of its vertices, when that centre
//      lies within `max_via_shift_mm` of it (moving points, whose place is
//      a function of a coordinate, stay);
//   4. a segment that still leaves the muscle is split at its middle by a
//      new fixed via point at the cross-section centre there, attached to
//      the bone of the kinematic chain between the segment's two bones that
//      it lies along: past a joint on the chain (its centre projected on
//      the segment's direction), the bone beyond it (a hamstring's
//      pelvis-to-tibia segment passes the femur: a point at mid-thigh rides
//      on the femur, not on the pelvis, or hip flexion would drag it
//      along). Without joint centres, the nearest of those bones' surfaces.
//      Recursively, up to `max_splits` levels.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/atlas/atlas.h"
#include "core/mesh/aabb_tree.h"

namespace mmm::atlas {

struct ActionLineFitOptions {
  double contact_mm = 3.0;
  double search_radius_mm = 60.0;
  // An end whose contact lies farther than this from it stays where the
  // model puts it (the segmented belly ends short of a long tendon: its
  // contact with the bone is not the attachment). About 1.5 times the
  // bone registrations' surface RMS (4.4-8.2 mm on the default atlas).
  double max_end_shift_mm = 12.0;
  // Likewise a via point whose cross-section centre lies farther than this
  // from it stays where the model puts it: through a thick muscle (gluteus
  // maximus behind the trochanter, psoas at the pelvic brim) the centre of
  // the section is not where the tendon runs over the bone. Lines drawn
  // from the muscle's own surface have no model place to keep: use
  // infinity for them.
  double max_via_shift_mm = 15.0;
  double slab_mm = 3.0;
  double section_radius_mm = 60.0;  // cross-section vertices farther than this are ignored
  int max_splits = 4;
  double sample_step_mm = 1.0;  // for the inside fraction of a segment
  double good_fraction = 0.95;  // segments at least this much inside are not split
  double min_segment_mm = 8.0;  // shorter segments are not split
  // The kinematic chain, bone -> parent bone (every joint's child -> parent),
  // and the centre of each bone's joint with its parent (rest pose, mm).
  // Empty: a split point attaches to one of its segment's two bones.
  std::map<std::string, std::string> parent_bone;
  std::map<std::string, Eigen::Vector3d> joint_centre;
  // True for a bone point under articular cartilage: no muscle attaches
  // there, so bundle vertices touching the bone at such points are not
  // contacts (empty: every bone point may be one).
  std::function<bool(const Eigen::Vector3d&)> articular;
};

struct ActionLineFitReport {
  std::string line;
  double inside_before = 0.0;  // fraction of the length inside the muscle
  double inside_after = 0.0;
  int points_added = 0;
  bool origin_on_contact = false;
  bool insertion_on_contact = false;
};

// Fits every action line of `muscle` (in place). `muscle_tree` is the tree of the
// muscle's surface, `inside` its inside test, `bones` the atlas bones' trees by name
// (every bone the lines name must be there).
std::vector<ActionLineFitReport> fit_action_lines(
    Muscle& muscle, const mesh::AabbTree& muscle_tree,
    const std::function<bool(const Eigen::Vector3d&)>& inside,
    const std::map<std::string, const mesh::AabbTree*>& bones,
    const ActionLineFitOptions& options = {});

}  // namespace mmm::atlas
