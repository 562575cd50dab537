#include "core/atlas/atlas.h"

#include <algorithm>

namespace mmm::atlas {
namespace {

template <class T>
const T* find_named(const std::vector<T>& items, std::string_view name) {
  const auto it = std::ranges::find_if(items, [&](const T& item) { return item.name == name; });
  return it == items.end() ? nullptr : &*it;
}

template <class T>
T* find_named(std::vector<T>& items, std::string_view name) {
  const auto it = std::ranges::find_if(items, [&](const T& item) { return item.name == name; });
  return it == items.end() ? nullptr : &*it;
}

template <class T>
void collect_tagged(const std::vector<T>& items, std::string_view tag,
                    std::vector<std::string>& names) {
  for (const T& item : items) {
    if (std::ranges::find(item.tags, tag) != item.tags.end()) names.push_back(item.name);
  }
}

template <class Enum, std::size_t N>
std::optional<Enum> from_name(std::string_view name,
                              const std::array<std::pair<Enum, std::string_view>, N>& table) {
  for (const auto& [value, text] : table) {
    if (text == name) return value;
  }
  return std::nullopt;
}

template <class Enum, std::size_t N>
std::string_view to_name(Enum value,
                         const std::array<std::pair<Enum, std::string_view>, N>& table) {
  for (const auto& [candidate, text] : table) {
    if (candidate == value) return text;
  }
  return "unknown";
}

constexpr std::array<std::pair<JointType, std::string_view>, 4> kJointTypes = {{
    {JointType::kWeld, "weld"},
    {JointType::kPin, "pin"},
    {JointType::kBall, "ball"},
    {JointType::kCustom, "custom"},
}};

constexpr std::array<std::pair<WrapShape, std::string_view>, 3> kWrapShapes = {{
    {WrapShape::kSphere, "sphere"},
    {WrapShape::kCylinder, "cylinder"},
    {WrapShape::kEllipsoid, "ellipsoid"},
}};

constexpr std::array<std::pair<FibreArchitecture, std::string_view>, 4> kArchitectures = {{
    {FibreArchitecture::kParallel, "parallel"},
    {FibreArchitecture::kPennate, "pennate"},
    {FibreArchitecture::kFanned, "fanned"},
    {FibreArchitecture::kCurved, "curved"},
}};

constexpr std::array<std::pair<StructureKind, std::string_view>, 2> kStructureKinds = {{
    {StructureKind::kCartilage, "cartilage"},
    {StructureKind::kLigament, "ligament"},
}};

}  // namespace

std::string_view structure_kind_name(StructureKind kind) { return to_name(kind, kStructureKinds); }
std::optional<StructureKind> structure_kind_from_name(std::string_view name) {
  return from_name(name, kStructureKinds);
}

std::string_view joint_type_name(JointType type) { return to_name(type, kJointTypes); }
std::optional<JointType> joint_type_from_name(std::string_view name) {
  return from_name(name, kJointTypes);
}
std::string_view wrap_shape_name(WrapShape shape) { return to_name(shape, kWrapShapes); }
std::optional<WrapShape> wrap_shape_from_name(std::string_view name) {
  return from_name(name, kWrapShapes);
}
std::string_view fibre_architecture_name(FibreArchitecture architecture) {
  return to_name(architecture, kArchitectures);
}
std::optional<FibreArchitecture> fibre_architecture_from_name(std::string_view name) {
  return from_name(name, kArchitectures);
}

const Bone* Atlas::find_bone(std::string_view element) const { return find_named(bones, element); }
const Joint* Atlas::find_joint(std::string_view element) const {
  return find_named(joints, element);
}
const Muscle* Atlas::find_muscle(std::string_view element) const {
  return find_named(muscles, element);
}
const Landmark* Atlas::find_landmark(std::string_view element) const {
  return find_named(landmarks, element);
}
const Marker* Atlas::find_marker(std::string_view element) const {
  return find_named(markers, element);
}
const Region* Atlas::find_region(std::string_view element) const {
  return find_named(regions, element);
}
const Structure* Atlas::find_structure(std::string_view element) const {
  return find_named(structures, element);
}
Bone* Atlas::find_bone(std::string_view element) { return find_named(bones, element); }
Muscle* Atlas::find_muscle(std::string_view element) { return find_named(muscles, element); }

std::vector<std::string> Atlas::find_by_tag(std::string_view tag) const {
  std::vector<std::string> names;
  collect_tagged(bones, tag, names);
  collect_tagged(muscles, tag, names);
  collect_tagged(structures, tag, names);
  collect_tagged(landmarks, tag, names);
  collect_tagged(regions, tag, names);
  return names;
}

}  // namespace mmm::atlas
