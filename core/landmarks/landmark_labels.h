#pragma once
// The atlas landmarks mmm knows, each with its anatomical definition and the
// labels other tools give it (3D Slicer point lists, motion-capture marker
// sets, radiology habits), in one table: the Slicer import matches labels
// with it, the landmark station's task shows the definitions, `mmm
// landmarks` and the docs print it.
//
// A label matches a landmark when, normalised (lower case; spaces, '-', '_',
// '.' dropped; "center" spelt "centre"), it equals the normalised atlas name
// or one of the landmark's labels. Labels of a right-leg landmark may carry
// the side before or after the stem ("R ASIS", "RASIS", "Right ASIS", "ASIS
// R", "Lateral Epicondyle Right"); a side-less leg label ("ankle centre")
// means the right leg, the leg of mmm's atlas. The two ASIS need their side.

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mmm::landmarks {

struct LandmarkLabels {
  std::string name;        // atlas landmark name, e.g. "lateral_epicondyle_r"
  std::string definition;  // anatomical definition, one or two sentences
  // "right", "left" or "" (midline): which side prefixes/suffixes its labels take.
  std::string side;
  // Label stems (written as people write them; the side is added as above),
  // e.g. {"Lateral Epicondyle", "LE", "Knee Lat", "LFE"}.
  std::vector<std::string> labels;
};

// The table, in the atlas's order (station landmarks first).
std::span<const LandmarkLabels> landmark_label_table();

// The entry of an atlas landmark name, or nullptr.
const LandmarkLabels* find_landmark_labels(std::string_view name);

// The definition of an atlas landmark name (a left-leg "..._l" name not in the
// table: its right twin's, with "right" read "left"), or "" when unknown.
std::string landmark_definition(std::string_view name);

// Lower case without spaces, '-', '_', '.' or tabs, "center" spelt "centre".
std::string normalise_label(std::string_view label);

// The atlas landmark a label names (see the file comment), or "" for none.
std::string landmark_for_label(std::string_view label);

// Every label form that matches `entry`, normalised, sorted (for tests and docs).
std::vector<std::string> normalised_labels(const LandmarkLabels& entry);

// The table as text for people: one line per landmark,
//   "  lateral_epicondyle_r  (Lateral Epicondyle R, RLE, R Knee Lat, ...): <definition>"
std::string landmark_label_table_text();

}  // namespace mmm::landmarks
