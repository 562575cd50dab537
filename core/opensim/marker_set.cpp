#include "core/opensim/marker_set.h"

#include <tinyxml2.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/opensim/text_parsing.h"

namespace mmm::opensim {

namespace {

using tinyxml2::XMLElement;

// An <IKTaskSet file=...> chain longer than this is taken for a cycle.
constexpr int kMaxFileDepth = 8;

std::string_view trimmed_text_of(const XMLElement& element) {
  const char* text = element.GetText();
  return text != nullptr ? trim_xml_space(text) : std::string_view();
}

std::string trimmed_name_of(const XMLElement& element) {
  const char* name = element.Attribute("name");
  return name != nullptr ? std::string(trim_xml_space(name)) : std::string();
}

// "line N: <Tag name="x">: "
std::string at(const XMLElement& element) {
  const char* name = element.Attribute("name");
  return "line " + std::to_string(element.GetLineNum()) + ": <" + element.Name() +
         (name != nullptr ? " name=\"" + std::string(name) + "\"" : "") + ">: ";
}

void parse_xml(tinyxml2::XMLDocument& document, std::string_view xml,
               const std::filesystem::path& name) {
  if (document.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    const char* detail = document.ErrorStr();
    throw IoError(name, "line " + std::to_string(document.ErrorLineNum()) + ": malformed XML: " +
                            (detail != nullptr ? detail : document.ErrorName()) +
                            "; hint: truncated or hand-edited file?");
  }
  if (document.RootElement() == nullptr) {
    throw IoError(name, "the XML has no root element, expected <OpenSimDocument>");
  }
}

bool parse_bool(const std::filesystem::path& name, const XMLElement& element) {
  const std::string value = ascii_lower(trimmed_text_of(element));
  if (value == "true" || value == "1") return true;
  if (value == "false" || value == "0") return false;
  throw IoError(name, at(element) + "expected true or false, got " +
                          quote_for_message(trimmed_text_of(element)));
}

// Body name from a 3.x <body> or a 4.x socket path.
std::string body_from(std::string_view text) {
  constexpr std::string_view kBodySet = "/bodyset/";
  if (text.substr(0, kBodySet.size()) == kBodySet) text.remove_prefix(kBodySet.size());
  while (!text.empty() && text.front() == '/') text.remove_prefix(1);
  return std::string(text);
}

MarkerDefinition parse_marker(const std::filesystem::path& name, const XMLElement& element) {
  MarkerDefinition marker;
  marker.name = trimmed_name_of(element);
  if (marker.name.empty()) {
    throw IoError(name, at(element) +
                            "the marker has no name attribute; the IK and Scale tools "
                            "match markers to the .trc by name");
  }
  const XMLElement* frame = element.FirstChildElement("socket_parent_frame");
  if (frame == nullptr) frame = element.FirstChildElement("body");
  if (frame == nullptr || trimmed_text_of(*frame).empty()) {
    throw IoError(name, at(element) +
                            "expected the body the marker sits on, as <socket_parent_frame> "
                            "(OpenSim 4) or <body> (OpenSim 3); found none or an empty one");
  }
  marker.body = body_from(trimmed_text_of(*frame));
  const XMLElement* location = element.FirstChildElement("location");
  if (location == nullptr) {
    throw IoError(name, at(element) + "no <location>; expected 3 numbers (m, body frame)");
  }
  const std::vector<std::string_view> words = split_xml_words(trimmed_text_of(*location));
  if (words.size() != 3) {
    throw IoError(name, at(*location) + "expected 3 numbers (x y z in m) in the location of " +
                            quote_for_message(marker.name) + ", got " +
                            std::to_string(words.size()));
  }
  for (int i = 0; i < 3; ++i) {
    double value = 0.0;
    if (!parse_double_token(words[static_cast<std::size_t>(i)], value) || !std::isfinite(value)) {
      throw IoError(name, at(*location) + "coordinate " + std::to_string(i) + " of " +
                              quote_for_message(marker.name) + " is " +
                              quote_for_message(words[static_cast<std::size_t>(i)]) +
                              ", expected a finite number (m)");
    }
    marker.location(i) = value;
  }
  if (const XMLElement* fixed = element.FirstChildElement("fixed"); fixed != nullptr) {
    marker.fixed = parse_bool(name, *fixed);
  }
  return marker;
}

const XMLElement* find_marker_set(const XMLElement& root) {
  const std::string_view root_name = root.Name();
  if (root_name == "MarkerSet") return &root;
  if (root_name != "OpenSimDocument") return nullptr;
  if (const XMLElement* set = root.FirstChildElement("MarkerSet"); set != nullptr) return set;
  const XMLElement* model = root.FirstChildElement("Model");
  return model != nullptr ? model->FirstChildElement("MarkerSet") : nullptr;
}

const XMLElement* find_task_set(const XMLElement& root) {
  const std::string_view root_name = root.Name();
  if (root_name == "IKTaskSet") return &root;
  const XMLElement* tool = &root;
  if (root_name == "OpenSimDocument") {
    if (const XMLElement* set = root.FirstChildElement("IKTaskSet"); set != nullptr) return set;
    tool = root.FirstChildElement("InverseKinematicsTool");
  } else if (root_name != "InverseKinematicsTool") {
    return nullptr;
  }
  return tool != nullptr ? tool->FirstChildElement("IKTaskSet") : nullptr;
}

std::map<std::string, IkMarkerWeight> parse_tasks(std::string_view xml,
                                                  const std::filesystem::path& name, int depth) {
  tinyxml2::XMLDocument document;
  parse_xml(document, xml, name);
  const XMLElement* set = find_task_set(*document.RootElement());
  if (set == nullptr) {
    throw IoError(name, "no <IKTaskSet> found under <" +
                            std::string(document.RootElement()->Name()) +
                            ">; expected <OpenSimDocument><InverseKinematicsTool><IKTaskSet> "
                            "(an IK setup) or <IKTaskSet> (a task-set file)");
  }
  const char* reference = set->Attribute("file");
  if (reference != nullptr && !trim_xml_space(reference).empty()) {
    if (depth >= kMaxFileDepth) {
      throw IoError(name, at(*set) + "task-set files refer to each other more than " +
                              std::to_string(kMaxFileDepth) + " deep; a cycle?");
    }
    const std::filesystem::path referenced =
        name.parent_path() / std::string(trim_xml_space(reference));
    return parse_tasks(read_whole_text_file(referenced, "an OpenSim XML file"), referenced,
                       depth + 1);
  }
  std::map<std::string, IkMarkerWeight> weights;
  const XMLElement* objects = set->FirstChildElement("objects");
  if (objects == nullptr) return weights;
  for (const XMLElement* task = objects->FirstChildElement("IKMarkerTask"); task != nullptr;
       task = task->NextSiblingElement("IKMarkerTask")) {
    const std::string marker = trimmed_name_of(*task);
    if (marker.empty()) {
      throw IoError(name, at(*task) + "the task has no name attribute; expected the marker name");
    }
    IkMarkerWeight weight;
    if (const XMLElement* apply = task->FirstChildElement("apply"); apply != nullptr) {
      weight.apply = parse_bool(name, *apply);
    }
    if (const XMLElement* value = task->FirstChildElement("weight"); value != nullptr) {
      if (!parse_double_token(trimmed_text_of(*value), weight.weight) ||
          !std::isfinite(weight.weight) || weight.weight < 0.0) {
        throw IoError(name, at(*value) + "the weight of " + quote_for_message(marker) + " is " +
                                quote_for_message(trimmed_text_of(*value)) +
                                ", expected a finite number >= 0");
      }
    }
    if (!weights.emplace(marker, weight).second) {
      throw IoError(name, at(*task) + "a second task for marker " + quote_for_message(marker) +
                              "; expected one task per marker");
    }
  }
  return weights;
}

}  // namespace

std::vector<MarkerDefinition> read_marker_set(const std::filesystem::path& file) {
  return parse_marker_set(read_whole_text_file(file, "an OpenSim XML file"), file);
}

std::vector<MarkerDefinition> parse_marker_set(std::string_view xml,
                                               const std::filesystem::path& name_for_messages) {
  tinyxml2::XMLDocument document;
  parse_xml(document, xml, name_for_messages);
  const XMLElement* set = find_marker_set(*document.RootElement());
  if (set == nullptr) {
    throw IoError(name_for_messages, "no <MarkerSet> found under <" +
                                         std::string(document.RootElement()->Name()) +
                                         ">; expected <OpenSimDocument><MarkerSet> (or a model's "
                                         "<OpenSimDocument><Model><MarkerSet>)");
  }
  std::vector<MarkerDefinition> markers;
  const XMLElement* objects = set->FirstChildElement("objects");
  if (objects == nullptr) return markers;
  std::set<std::string> seen;
  for (const XMLElement* element = objects->FirstChildElement("Marker"); element != nullptr;
       element = element->NextSiblingElement("Marker")) {
    MarkerDefinition marker = parse_marker(name_for_messages, *element);
    if (!seen.insert(marker.name).second) {
      throw IoError(name_for_messages, at(*element) + "the marker name " +
                                           quote_for_message(marker.name) +
                                           " is used twice; expected unique names");
    }
    markers.push_back(std::move(marker));
  }
  return markers;
}

std::map<std::string, IkMarkerWeight> read_ik_task_weights(const std::filesystem::path& setup) {
  return parse_tasks(read_whole_text_file(setup, "an OpenSim XML file"), setup, 0);
}

std::map<std::string, IkMarkerWeight> parse_ik_task_weights(
    std::string_view xml, const std::filesystem::path& name_for_messages) {
  return parse_tasks(xml, name_for_messages, 0);
}

}  // namespace mmm::opensim
