#pragma once
// 3D Slicer Markups JSON (.mrk.json, schema markups-schema-v1.0.3): point
// lists placed on a CT or MR volume, read as a LandmarkSet in the patient
// frame (RAS, mm) and written back.
//
// The parts read (everything else is ignored):
//   {"@schema": ".../markups-schema-v1.0.x.json#",
//    "markups": [{"type": "Fiducial",            point list; other types skipped
//                 "coordinateSystem": "LPS",     or "RAS"; missing: LPS (Slicer's default)
//                 "coordinateUnits": "mm",       "mm" (missing: mm), "um" or "m"
//                 "controlPoints": [{"label": "F-1", "position": [x, y, z],
//                                    "positionStatus": "defined"}, ...]}]}
// LPS -> RAS negates x and y. A point whose positionStatus is "undefined"
// (placed in the list but never set) or "preview" (still being dragged) is
// skipped with a note; no positionStatus (files of schema 1.0.0) means defined.
//
// Labels become landmark names (match_landmark_name): exactly, else ignoring
// case, spaces, '-', '_', '.' and the spelling "center"/"centre"
// ("Femoral Head Center R" -> femoral_head_centre_r), else through the alias
// table of MarkupsReadOptions. A label that matches nothing is kept as it is,
// with a note, so that a later check (landmark_validation.h) names it.

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/landmarks/landmark_set.h"

namespace mmm::landmarks {

// The default alias table, keyed by the normalised label (lower case, no
// spaces, '-', '_' or '.', "center" spelt "centre"). Side-less names mean the
// right leg, the leg of mmm's atlas:
//   femoralhead, femoralheadcentre, hipcentre, hjc      -> femoral_head_centre_r
//   patella, patellacentre                               -> patella_centre_r
//   ankle, anklecentre, ajc                              -> ankle_centre_r
//   knee, kneecentre, kjc                                -> knee_centre_r
// and the same with a trailing "r" / "right" ("femoralheadright").
std::map<std::string, std::string> default_landmark_aliases();

struct MarkupsReadOptions {
  // Landmark names labels are matched against.
  std::vector<std::string> landmark_names = {"femoral_head_centre_r", "patella_centre_r",
                                             "ankle_centre_r", "knee_centre_r"};
  // Normalised label -> landmark name (see default_landmark_aliases).
  std::map<std::string, std::string> aliases = default_landmark_aliases();
};

// The landmark name for a Slicer label, or "" when nothing matches (see the
// file comment for the order of the rules).
std::string match_landmark_name(std::string_view label, const MarkupsReadOptions& options = {});

struct MarkupsReadResult {
  LandmarkSet landmarks;  // frame "patient" (RAS, mm), source "slicer_markups", file order
  // One sentence per point skipped, label renamed or kept unmatched, markup of
  // another type ignored.
  std::vector<std::string> notes;
};

// Reads a .mrk.json file. Throws IoError naming the file and the JSON path
// ("markups[0].controlPoints[2].position must be 3 finite numbers, got ...")
// for: a missing or unreadable file, invalid JSON, no "markups" array, a
// point list whose coordinateSystem is not LPS/RAS or whose coordinateUnits
// are not mm/um/m, a control point without a 3-number position, no point
// list at all, or two points that become the same landmark name.
MarkupsReadResult read_slicer_markups(const std::filesystem::path& file,
                                      const MarkupsReadOptions& options = {});

struct MarkupsWriteOptions {
  // "LPS" (what Slicer 5 writes) or "RAS".
  std::string coordinate_system = "LPS";
};

// Writes `set` as one Slicer point list (type "Fiducial", mm, every point
// "defined", labels = landmark names, ids "1", "2", ...), numbers as the
// shortest text that reads back exactly. Positions are taken as RAS patient
// coordinates. Throws InvalidInputError for an invalid set (landmark_set.h)
// or coordinate system, IoError naming the file when it cannot be written.
void write_slicer_markups(const LandmarkSet& set, const std::filesystem::path& file,
                          const MarkupsWriteOptions& options = {});

}  // namespace mmm::landmarks
