#pragma once
// Values typed on a command line ("--input threshold=0.5", "mmm study set
// DIR decimate.target_faces=2000") turned into typed values, and the stable
// serialisation of value-typed artifacts (Number, Integer, String, Bool).

#include <string>
#include <string_view>

#include "workflow/node_spec.h"
#include "workflow/port_type.h"

namespace mmm::workflow {

// Parses `text` as a value of `type` (a value type). Numbers must be finite
// and use the whole text; booleans are true/false. Throws InvalidInputError
// saying what was expected, naming `what` (e.g. "study input 'threshold'").
ParamValue parse_value_text(PortType type, std::string_view text, std::string_view what);

// Parses `text` as a value for the parameter `spec` and checks it against the
// spec (type, range, choices). Throws InvalidInputError naming `what` with the
// reason and the accepted values.
ParamValue parse_param_text(const ParamSpec& spec, std::string_view text, std::string_view what);

// The artifact bytes of a value: JSON text (a number in shortest round-trip
// form, an integer, a JSON string, true/false).
std::string value_artifact_bytes(const ParamValue& value);

}  // namespace mmm::workflow
