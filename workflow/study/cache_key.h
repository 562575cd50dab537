#pragma once
// When may a node's earlier result be reused? Exactly when its cache key is
// unchanged: node type + implementation version + every parameter (defaults
// applied, normalised to the declared type) + the content hash of every
// connected input. Nothing about paths, times or hosts enters the key, so a
// moved study folder, a re-run on another machine or a YAML reformatting
// reuses everything, and any real change is seen.

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "workflow/node_spec.h"

namespace mmm::workflow {

struct CacheKeyParts {
  std::string node_type;
  int version = 0;
  std::map<std::string, ParamValue> params;         // effective values of every parameter
  std::map<std::string, std::string> input_hashes;  // connected port -> artifact hash
};

// Every declared parameter with its effective value: `given` where present,
// else the default; integers given for number parameters become doubles so
// that 2000 and 2000.0 are the same key. Throws InvalidInputError on an
// unknown name or a value the spec rejects.
std::map<std::string, ParamValue> effective_params(const NodeSpec& spec,
                                                   const std::map<std::string, ParamValue>& given);

// Canonical JSON of the parts (object keys sorted; values typed), the text
// that is hashed and that `mmm explain` compares.
nlohmann::json cache_key_json(const CacheKeyParts& parts);
CacheKeyParts cache_key_parts_from_json(const nlohmann::json& json);

// SHA-256 (hex) of cache_key_json(parts).dump().
std::string cache_key(const CacheKeyParts& parts);

// JSON form of a parameter value ({"number": 0.5}, {"integer": 3}, ...).
nlohmann::json param_value_json(const ParamValue& value);
ParamValue param_value_from_json(const nlohmann::json& json);

// Differences between an earlier key and the current one, one sentence each
// ("parameter 'target_faces' changed from 5000 to 2000"); empty when equal.
std::vector<std::string> describe_key_changes(const CacheKeyParts& before,
                                              const CacheKeyParts& now);

}  // namespace mmm::workflow
