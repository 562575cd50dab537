#include "worklists/operators.h"

#include <nlohmann/json.hpp>
#include <random>

#include "core/bounded_json.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/hash/sha256.h"
#include "workflow/host_and_time.h"
#include "worklists/task_actions.h"

namespace mmm::worklists {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

constexpr const char* kFormat = "mmm-operators";

std::string random_token() {
  std::random_device source;
  std::uniform_int_distribution<int> nibble(0, 15);
  std::string token;
  for (int i = 0; i < 64; ++i) token += "0123456789abcdef"[nibble(source)];
  return token;
}

void write_operators(const fs::path& root, const std::vector<OperatorRecord>& operators) {
  Json list = Json::array();
  for (const OperatorRecord& record : operators) {
    list.push_back({{"name", record.name},
                    {"token_sha256", record.token_sha256},
                    {"created_at", record.created_at},
                    {"role", record.role}});
  }
  const Json document = {{"format", kFormat}, {"version", 1}, {"operators", list}};
  fs::create_directories(operators_file(root).parent_path());
  write_file_atomically(operators_file(root), document.dump(2) + "\n", "the operators file");
}

bool same_hash(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    difference |= static_cast<unsigned char>(a[i] ^ b[i]);
  }
  return difference == 0;
}

}  // namespace

fs::path operators_file(const fs::path& root) { return root / ".mmm" / "operators.json"; }

std::vector<OperatorRecord> read_operators(const fs::path& root) {
  const fs::path file = operators_file(root);
  std::error_code error;
  if (!fs::exists(file, error)) return {};
  Json document;
  try {
    document = parse_json(read_file_bytes(file, fs::file_size(file)));
  } catch (const Json::parse_error& e) {
    throw IoError(file, std::string("is not valid JSON: ") + e.what() +
                            "; hint: restore it or add the operators again");
  }
  if (!document.is_object() || document.value("format", "") != kFormat ||
      !document.contains("operators") || !document["operators"].is_array()) {
    throw IoError(file, "is not an mmm operators file (format \"mmm-operators\" with a list)");
  }
  std::vector<OperatorRecord> operators;
  for (const Json& entry : document["operators"]) {
    if (!entry.is_object() || !entry.contains("name") || !entry["name"].is_string() ||
        !entry.contains("token_sha256") || !entry["token_sha256"].is_string()) {
      throw IoError(file, "operators[" + std::to_string(operators.size()) +
                              "] needs a 'name' and a 'token_sha256' string");
    }
    const std::string role = entry.value("role", kOperatorRole);
    if (role != kOperatorRole && role != kSupervisorRole) {
      throw IoError(file, "operators[" + std::to_string(operators.size()) + "] has role '" + role +
                              R"('; a role is "operator" or "supervisor")");
    }
    operators.push_back({entry["name"].get<std::string>(), entry["token_sha256"].get<std::string>(),
                         entry.value("created_at", ""), role});
  }
  return operators;
}

std::string add_operator(const fs::path& root, const std::string& name, bool replace,
                         const std::string& role) {
  check_operator_name(name);
  if (role != kOperatorRole && role != kSupervisorRole) {
    throw InvalidInputError("role '" + role + "' is not known; hint: operator or supervisor");
  }
  std::error_code error;
  if (!fs::is_directory(root, error)) {
    throw IoError(root, "is not a folder; hint: --root names the folder that holds the studies");
  }
  std::vector<OperatorRecord> operators = read_operators(root);
  std::string token = random_token();
  const OperatorRecord record{name, hash::sha256_hex(token), workflow::utc_now(), role};
  bool found = false;
  for (OperatorRecord& existing : operators) {
    if (existing.name != name) continue;
    if (!replace) {
      throw InvalidInputError("operator '" + name + "' already exists under " + root.string() +
                              "; hint: --replace gives them a new token");
    }
    existing = record;
    found = true;
  }
  if (!found) operators.push_back(record);
  write_operators(root, operators);
  return token;
}

std::optional<std::string> operator_for_token(const fs::path& root, const std::string& token) {
  if (token.empty()) return std::nullopt;
  const std::string digest = hash::sha256_hex(token);
  std::optional<std::string> found;
  for (const OperatorRecord& record : read_operators(root)) {
    if (same_hash(record.token_sha256, digest)) found = record.name;
  }
  return found;
}

bool is_supervisor(const fs::path& root, const std::string& name) {
  std::error_code error;
  if (!fs::exists(operators_file(root), error)) return false;
  for (const OperatorRecord& record : read_operators(root)) {
    if (record.name == name) return record.role == kSupervisorRole;
  }
  return false;
}

void check_registered_operator(const fs::path& root, const std::string& name) {
  check_operator_name(name);
  std::error_code error;
  if (!fs::exists(operators_file(root), error)) return;
  std::string known;
  for (const OperatorRecord& record : read_operators(root)) {
    if (record.name == name) return;
    known += (known.empty() ? "" : ", ") + record.name;
  }
  throw InvalidInputError("operator '" + name + "' is not registered under " + root.string() +
                          " (operators: " + known + "); hint: 'mmm operator add " + name +
                          " --root " + root.string() + "'");
}

}  // namespace mmm::worklists
