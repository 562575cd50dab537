#pragma once
// A node type's contract, declared as a value: name, implementation version,
// description, typed inputs and outputs, and parameters with type, default,
// range or allowed values and description. The engine checks workflows
// against it, `mmm nodes` prints it, and the cache key includes the version.
//
//   static NodeSpec spec() {
//     return NodeSpec{"decimate_mesh", 1, "Lower-resolution copy of a mesh"}
//         .input<port::Mesh>("mesh", "Surface to simplify")
//         .param<std::int64_t>("target_faces", 5000, "Faces to reach", {.min = 4})
//         .output<port::Mesh>("decimated", "Simplified surface");
//   }

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "workflow/port_type.h"

namespace mmm::workflow {

struct PortSpec {
  std::string name;
  PortType type;
  std::string description;
  bool required = true;  // inputs only: an optional input may stay unconnected
};

enum class ParamType { kNumber, kInteger, kString, kBool, kEnum };
std::string_view param_type_name(ParamType type);

using ParamValue = std::variant<double, std::int64_t, std::string, bool>;

// Human-readable text of a value ("0.5", "12", "slicing", "true").
std::string param_value_text(const ParamValue& value);

// Range of a number or integer parameter, inclusive.
struct ParamRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
};

struct ParamSpec {
  std::string name;
  ParamType type;
  ParamValue default_value;
  std::string description;
  std::string unit;                  // e.g. "mm", "deg"; empty when dimensionless
  ParamRange range;                  // kNumber, kInteger
  std::vector<std::string> choices;  // kEnum: the allowed values

  // std::nullopt when `value` is acceptable, else why not (type, range, choice).
  [[nodiscard]] std::optional<std::string> check(const ParamValue& value) const;
};

// What one execution of a node type needs on a cluster node (Slurm's
// --cpus-per-task and --mem): declared by the node type, used by the Slurm
// executor (slurm_executor.h); local runs ignore it.
struct NodeResources {
  int threads = 1;
  int memory_mb = 2048;
};

class NodeSpec {
 public:
  NodeSpec(std::string name, int version, std::string description);

  template <class Tag>
  NodeSpec& input(std::string name, std::string description) {
    return add_input({std::move(name), Tag::kType, std::move(description), true});
  }
  template <class Tag>
  NodeSpec& optional_input(std::string name, std::string description) {
    return add_input({std::move(name), Tag::kType, std::move(description), false});
  }
  template <class Tag>
  NodeSpec& output(std::string name, std::string description) {
    return add_output({std::move(name), Tag::kType, std::move(description), true});
  }

  // Typed parameters: T is double, std::int64_t, bool or std::string.
  template <class T>
  NodeSpec& param(std::string name, T default_value, std::string description, ParamRange range = {},
                  std::string unit = {});
  NodeSpec& param_enum(std::string name, std::string default_choice,
                       std::vector<std::string> choices, std::string description);

  // A manual node waits for a person (e.g. the landmark station) instead of
  // computing: the engine opens a task and the study pauses.
  NodeSpec& manual(bool is_manual = true);

  // Threads and memory one execution needs (see NodeResources). Throws
  // InvalidInputError for threads < 1 or memory < 64 MB.
  NodeSpec& resources(int threads, int memory_mb);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] int version() const { return version_; }
  [[nodiscard]] const std::string& description() const { return description_; }
  [[nodiscard]] bool is_manual() const { return manual_; }
  [[nodiscard]] const NodeResources& resources() const { return resources_; }
  [[nodiscard]] const std::vector<PortSpec>& inputs() const { return inputs_; }
  [[nodiscard]] const std::vector<PortSpec>& outputs() const { return outputs_; }
  [[nodiscard]] const std::vector<ParamSpec>& params() const { return params_; }

  [[nodiscard]] const PortSpec* find_input(std::string_view name) const;
  [[nodiscard]] const PortSpec* find_output(std::string_view name) const;
  [[nodiscard]] const ParamSpec* find_param(std::string_view name) const;

 private:
  NodeSpec& add_input(PortSpec port);
  NodeSpec& add_output(PortSpec port);
  NodeSpec& add_param(ParamSpec param);

  std::string name_;
  int version_;
  std::string description_;
  bool manual_ = false;
  NodeResources resources_;
  std::vector<PortSpec> inputs_;
  std::vector<PortSpec> outputs_;
  std::vector<ParamSpec> params_;
};

template <class T>
NodeSpec& NodeSpec::param(std::string name, T default_value, std::string description,
                          ParamRange range, std::string unit) {
  ParamSpec spec{std::move(name),
                 ParamType::kNumber,
                 ParamValue{},
                 std::move(description),
                 std::move(unit),
                 range,
                 {}};
  if constexpr (std::is_same_v<T, double>) {
    spec.type = ParamType::kNumber;
    spec.default_value = default_value;
  } else if constexpr (std::is_same_v<T, std::int64_t> || std::is_same_v<T, int>) {
    spec.type = ParamType::kInteger;
    spec.default_value = static_cast<std::int64_t>(default_value);
  } else if constexpr (std::is_same_v<T, bool>) {
    spec.type = ParamType::kBool;
    spec.default_value = default_value;
  } else {
    static_assert(std::is_convertible_v<T, std::string>,
                  "parameters are double, std::int64_t, bool or std::string");
    spec.type = ParamType::kString;
    spec.default_value = std::string(default_value);
  }
  return add_param(std::move(spec));
}

}  // namespace mmm::workflow
