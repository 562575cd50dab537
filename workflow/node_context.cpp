#include "workflow/node_context.h"

#include <fstream>
#include <iterator>

#include "core/errors.h"

namespace mmm::workflow {

NodeContext::NodeContext(const NodeSpec& spec, std::map<std::string, ArtifactRef> inputs,
                         std::map<std::string, ParamValue> params,
                         std::filesystem::path scratch_dir, Channels channels)
    : spec_(&spec),
      inputs_(std::move(inputs)),
      params_(std::move(params)),
      scratch_dir_(std::move(scratch_dir)),
      channels_(std::move(channels)) {}

bool NodeContext::has_input(std::string_view port) const {
  return inputs_.find(std::string(port)) != inputs_.end();
}

const ArtifactRef& NodeContext::input(std::string_view port) const {
  const auto it = inputs_.find(std::string(port));
  if (it == inputs_.end()) {
    throw InvalidInputError(
        "node type " + spec_->name() + ": input '" + std::string(port) +
        (spec_->find_input(port) != nullptr ? "' is not connected" : "' is not declared"));
  }
  return it->second;
}

std::string NodeContext::input_bytes(std::string_view port) const {
  const ArtifactRef& ref = input(port);
  std::ifstream in(ref.path, std::ios::binary);
  if (!in) throw IoError(ref.path, "cannot read the artifact of input '" + std::string(port) + "'");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const ParamValue& NodeContext::param(std::string_view name, ParamType expected) const {
  const ParamSpec* spec = spec_->find_param(name);
  if (spec == nullptr) {
    throw InvalidInputError("node type " + spec_->name() + ": no parameter '" + std::string(name) +
                            "'");
  }
  const bool compatible =
      spec->type == expected || (expected == ParamType::kString && spec->type == ParamType::kEnum);
  if (!compatible) {
    throw InvalidInputError("node type " + spec_->name() + ": parameter '" + std::string(name) +
                            "' is " + std::string(param_type_name(spec->type)) + ", read as " +
                            std::string(param_type_name(expected)));
  }
  const auto it = params_.find(std::string(name));
  return it != params_.end() ? it->second : spec->default_value;
}

double NodeContext::number(std::string_view name) const {
  const ParamValue& value = param(name, ParamType::kNumber);
  if (const auto* integer_value = std::get_if<std::int64_t>(&value)) {
    return static_cast<double>(*integer_value);
  }
  return std::get<double>(value);
}

std::int64_t NodeContext::integer(std::string_view name) const {
  return std::get<std::int64_t>(param(name, ParamType::kInteger));
}

const std::string& NodeContext::text(std::string_view name) const {
  return std::get<std::string>(param(name, ParamType::kString));
}

bool NodeContext::flag(std::string_view name) const {
  return std::get<bool>(param(name, ParamType::kBool));
}

const PortSpec& NodeContext::output_port(std::string_view port) {
  const PortSpec* spec = spec_->find_output(port);
  if (spec == nullptr) {
    throw InvalidInputError("node type " + spec_->name() + ": no output '" + std::string(port) +
                            "'");
  }
  if (outputs_.contains(spec->name)) {
    throw InvalidInputError("node type " + spec_->name() + ": output '" + spec->name +
                            "' set twice");
  }
  return *spec;
}

void NodeContext::set_output(std::string_view port, std::string_view bytes) {
  const PortSpec& spec = output_port(port);
  const std::string hash = channels_.store(bytes);
  outputs_[spec.name] = ArtifactRef{spec.type, hash, {}};
}

void NodeContext::set_output_file(std::string_view port, const std::filesystem::path& file) {
  const PortSpec& spec = output_port(port);
  const std::string hash = channels_.store_file(file);
  outputs_[spec.name] = ArtifactRef{spec.type, hash, {}};
}

void NodeContext::progress(std::int64_t done, std::int64_t total, std::string_view what) const {
  if (channels_.progress) channels_.progress(done, total, what);
}

void NodeContext::log(LogLevel level, std::string_view message) const {
  if (channels_.log) channels_.log(level, message);
}

}  // namespace mmm::workflow
