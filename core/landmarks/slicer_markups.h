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
// ("Femoral Head Center R" -> femoral_head_centre_r), else through the label
// table of landmark_labels.h ("RASIS", "R Knee Lat", "Calcaneus", ...), else
// through the extra aliases of MarkupsReadOptions. A label that matches
// nothing is an error listing every landmark, its labels and its definition:
// a point silently dropped would scale the atlas on fewer landmarks than the
// person who placed them meant.

#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/landmarks/landmark_set.h"

namespace mmm::landmarks {

struct MarkupsReadOptions {
  // Normalised label (landmark_labels.h: normalise_label) -> landmark name,
  // tried after the label table: a site's own habits.
  std::map<std::string, std::string> aliases;
};

// The landmark name for a Slicer label, or "" when nothing matches (see the
// file comment for the order of the rules).
std::string match_landmark_name(std::string_view label, const MarkupsReadOptions& options = {});

struct MarkupsReadResult {
  LandmarkSet landmarks;  // frame "patient" (RAS, mm), source "slicer_markups", file order
  // One sentence per point skipped, label renamed, markup of another type
  // ignored.
  std::vector<std::string> notes;
  // The coordinate system the point lists declared ("LPS" when they declared
  // none, Slicer's default), for the hint of a check that finds the points
  // mirrored (landmark_validation.h: check_landmark_anatomy).
  std::string coordinate_system = "LPS";
};

// Reads a .mrk.json file. Throws IoError naming the file and the JSON path
// ("markups[0].controlPoints[2].position must be 3 finite numbers, got ...")
// for: a missing or unreadable file, invalid JSON, no "markups" array, a
// point list whose coordinateSystem is not LPS/RAS or whose coordinateUnits
// are not mm/um/m, a control point without a 3-number position, a label that
// names no landmark (the message lists the table of landmark_labels.h), no
// point list at all, or two points that become the same landmark name.
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
