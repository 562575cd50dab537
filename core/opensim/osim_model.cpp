#include "core/opensim/osim_model.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
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

constexpr int kFirstVersion3 = 30000;
constexpr int kFirstVersion4 = 40000;
// Offset frames hanging off offset frames deeper than this are taken for a cycle.
constexpr int kMaxFrameDepth = 64;

constexpr std::array<std::string_view, 6> kFunctionTags = {
    "Constant",   "LinearFunction",          "PolynomialFunction",
    "SimmSpline", "PiecewiseLinearFunction", "MultiplierFunction"};

bool is_function_tag(std::string_view tag) {
  return std::find(kFunctionTags.begin(), kFunctionTags.end(), tag) != kFunctionTags.end();
}

constexpr std::string_view kSupportedFunctions =
    "Constant, LinearFunction, PolynomialFunction, SimmSpline, PiecewiseLinearFunction, "
    "MultiplierFunction";

// Component path segments, without empty, "." and ".." parts.
std::vector<std::string_view> split_path(std::string_view path) {
  std::vector<std::string_view> segments;
  std::size_t pos = 0;
  while (pos <= path.size()) {
    std::size_t end = path.find('/', pos);
    if (end == std::string_view::npos) end = path.size();
    const std::string_view segment = trim_xml_space(path.substr(pos, end - pos));
    if (!segment.empty() && segment != "." && segment != "..") segments.push_back(segment);
    pos = end + 1;
  }
  return segments;
}

// Last segment of a component path ("/jointset/knee_r/knee_angle_r" -> "knee_angle_r").
std::string last_segment(std::string_view path) {
  const std::vector<std::string_view> segments = split_path(path);
  return segments.empty() ? std::string() : std::string(segments.back());
}

const char* text_of(const XMLElement& element) {
  const char* text = element.GetText();
  return text != nullptr ? text : "";
}

std::string name_of(const XMLElement& element) {
  const char* name = element.Attribute("name");
  return name != nullptr ? std::string(name) : std::string();
}

// "<Tag name="x">"
std::string describe(const XMLElement& element) {
  const char* name = element.Attribute("name");
  return "<" + std::string(element.Name()) +
         (name != nullptr ? " name=\"" + std::string(name) + "\"" : "") + ">";
}

// "<tag>" or "<tag> of <Owner name="x">" with the nearest named ancestor.
std::string label(const XMLElement& element) {
  std::string out = describe(element);
  if (element.Attribute("name") != nullptr) return out;
  for (const tinyxml2::XMLNode* node = element.Parent(); node != nullptr; node = node->Parent()) {
    const XMLElement* parent = node->ToElement();
    if (parent != nullptr && parent->Attribute("name") != nullptr) {
      return out + " of " + describe(*parent);
    }
  }
  return out;
}

template <typename F>
void for_each_child(const XMLElement* parent, F&& visit) {
  if (parent == nullptr) return;
  for (const XMLElement* child = parent->FirstChildElement(); child != nullptr;
       child = child->NextSiblingElement()) {
    visit(*child);
  }
}

// Children of <Set><objects> (all element kinds), or nothing.
template <typename F>
void for_each_object(const XMLElement* set, F&& visit) {
  if (set == nullptr) return;
  for_each_child(set->FirstChildElement("objects"), std::forward<F>(visit));
}

MotionType motion_type_of_axis_use(bool rotation) {
  return rotation ? MotionType::kRotational : MotionType::kTranslational;
}

// True when f(q) = q: LinearFunction of slope 1, possibly inside a
// MultiplierFunction of scale 1 (OpenSim's test for "the coordinate is the
// axis displacement").
bool is_unit_slope(const Function& function) {
  if (const auto* linear = function.get_if<LinearFunction>()) return linear->slope == 1.0;
  if (const auto* multiplier = function.get_if<MultiplierFunction>()) {
    const auto* inner = multiplier->function().get_if<LinearFunction>();
    return inner != nullptr && inner->slope * multiplier->scale() == 1.0;
  }
  return false;
}

// Motion types fixed by the joint type, in coordinate order.
std::vector<MotionType> motion_types_of_joint_type(std::string_view type) {
  constexpr auto kR = MotionType::kRotational;
  constexpr auto kT = MotionType::kTranslational;
  if (type == "PinJoint") return {kR};
  if (type == "SliderJoint") return {kT};
  if (type == "UniversalJoint") return {kR, kR};
  if (type == "BallJoint" || type == "GimbalJoint" || type == "EllipsoidJoint") {
    return {kR, kR, kR};
  }
  if (type == "ScapulothoracicJoint") return {kR, kR, kR, kR};
  if (type == "FreeJoint") return {kR, kR, kR, kT, kT, kT};
  if (type == "PlanarJoint") return {kR, kT, kT};
  return {};
}

Eigen::Vector3d xyz_angles(const Eigen::Matrix3d& rotation) {
  const double sin_b = std::clamp(rotation(0, 2), -1.0, 1.0);
  return {std::atan2(-rotation(1, 2), rotation(2, 2)), std::asin(sin_b),
          std::atan2(-rotation(0, 1), rotation(0, 0))};
}

// A PhysicalOffsetFrame element and where it lives.
struct OffsetFrameEntry {
  enum class Scope { kJoint, kBody, kModel };
  const XMLElement* element = nullptr;
  std::string name;
  Scope scope = Scope::kModel;
  std::string owner;  // joint or body name
};

class OsimReader {
 public:
  OsimReader(std::string_view xml, std::filesystem::path path)
      : xml_(xml), path_(std::move(path)) {}

  OsimModel read() {
    if (document_.Parse(xml_.data(), xml_.size()) != tinyxml2::XML_SUCCESS) {
      const char* detail = document_.ErrorStr();
      throw IoError(path_,
                    "line " + std::to_string(document_.ErrorLineNum()) +
                        ": malformed XML: " + (detail != nullptr ? detail : document_.ErrorName()) +
                        " (truncated or hand-edited file? an .osim file is the XML "
                        "OpenSim writes)");
    }
    const XMLElement* root = document_.RootElement();
    if (root == nullptr || std::string_view(root->Name()) != "OpenSimDocument") {
      throw IoError(path_, "not an OpenSim model: the root element is " +
                               (root != nullptr ? describe(*root) : std::string("missing")) +
                               ", expected <OpenSimDocument> (is this an .osim file?)");
    }
    read_version(*root);
    const XMLElement* model = root->FirstChildElement("Model");
    if (model == nullptr) {
      fail(*root,
           "has no <Model>; expected <OpenSimDocument><Model name=\"...\"> (a setup or "
           "marker file rather than a model?)");
    }
    model_.source = path_;
    model_.version = version_;
    read_model_properties(*model);
    if (version_ >= kFirstVersion4) {
      read_bodies_4(*model);
      collect_offset_frames(*model);
      read_joints_4(*model);
    } else {
      read_bodies_and_joints_3(*model);
    }
    finish_joints();
    read_markers(*model);
    read_forces(*model);
    return std::move(model_);
  }

 private:
  // ------------------------------------------------------------ errors

  [[noreturn]] void fail(const XMLElement& element, const std::string& what) const {
    throw IoError(path_, "line " + std::to_string(element.GetLineNum()) + ": " + label(element) +
                             ": " + what);
  }

  // ------------------------------------------------------------ values

  std::vector<double> numbers(const XMLElement& element) const {
    std::vector<double> values;
    const std::vector<std::string_view> words = split_xml_words(text_of(element));
    values.reserve(words.size());
    for (std::size_t i = 0; i < words.size(); ++i) {
      double value = 0.0;
      if (!parse_double_token(words[i], value)) {
        fail(element, "value " + std::to_string(i + 1) + " is " + quote_for_message(words[i]) +
                          ", not a number");
      }
      if (!std::isfinite(value)) {
        fail(element, "value " + std::to_string(i + 1) + " is " + quote_for_message(words[i]) +
                          "; expected a finite number");
      }
      values.push_back(value);
    }
    return values;
  }

  std::vector<double> numbers(const XMLElement& element, std::size_t expected,
                              std::string_view meaning) const {
    std::vector<double> values = numbers(element);
    if (values.size() != expected) {
      fail(element, "holds " + std::to_string(values.size()) + " value" +
                        (values.size() == 1 ? "" : "s") + ", expected " + std::to_string(expected) +
                        " (" + std::string(meaning) + ")");
    }
    return values;
  }

  double scalar(const XMLElement& element) const {
    return numbers(element, 1, "one number").front();
  }

  Eigen::Vector3d vec3(const XMLElement& element) const {
    const std::vector<double> v = numbers(element, 3, "x y z");
    return {v[0], v[1], v[2]};
  }

  std::array<double, 2> range2(const XMLElement& element) const {
    const std::vector<double> v = numbers(element, 2, "min max");
    if (v[0] > v[1]) {
      fail(element, "minimum " + std::to_string(v[0]) + " exceeds maximum " + std::to_string(v[1]) +
                        "; expected 'min max'");
    }
    return {v[0], v[1]};
  }

  bool boolean(const XMLElement& element) const {
    const std::string value = ascii_lower(trim_xml_space(text_of(element)));
    if (value == "true" || value == "1") return true;
    if (value == "false" || value == "0") return false;
    fail(element, "holds " + quote_for_message(trim_xml_space(text_of(element))) +
                      ", expected true or false");
  }

  double scalar_or(const XMLElement& parent, const char* name, double fallback) const {
    const XMLElement* child = parent.FirstChildElement(name);
    return child != nullptr ? scalar(*child) : fallback;
  }

  Eigen::Vector3d vec3_or(const XMLElement& parent, const char* name,
                          const Eigen::Vector3d& fallback) const {
    const XMLElement* child = parent.FirstChildElement(name);
    return child != nullptr ? vec3(*child) : fallback;
  }

  bool boolean_or(const XMLElement& parent, const char* name, bool fallback) const {
    const XMLElement* child = parent.FirstChildElement(name);
    return child != nullptr ? boolean(*child) : fallback;
  }

  static std::string text_or(const XMLElement& parent, const char* name) {
    const XMLElement* child = parent.FirstChildElement(name);
    return child != nullptr ? std::string(trim_xml_space(text_of(*child))) : std::string();
  }

  const XMLElement& required(const XMLElement& parent, const char* name,
                             std::string_view hint) const {
    const XMLElement* child = parent.FirstChildElement(name);
    if (child == nullptr) {
      fail(parent, "has no <" + std::string(name) + ">; " + std::string(hint));
    }
    return *child;
  }

  // ------------------------------------------------------------ header

  void read_version(const XMLElement& root) {
    const char* text = root.Attribute("Version");
    if (text == nullptr) {
      fail(root,
           "has no Version attribute; expected e.g. Version=\"40000\" (OpenSim writes "
           "it; re-save the model with OpenSim)");
    }
    const std::string_view version_text = trim_xml_space(text);
    const char* end = version_text.data() + version_text.size();
    const auto [ptr, error] = std::from_chars(version_text.data(), end, version_);
    if (error != std::errc() || ptr != end) {
      fail(root,
           "Version=" + quote_for_message(text) + " is not an integer; expected e.g. \"40000\"");
    }
    if (version_ < kFirstVersion3) {
      fail(root, "Version " + std::to_string(version_) +
                     " is an OpenSim 2.x or older document; only 3.x (30000-39999) and 4.x "
                     "(40000+) models are read. Hint: open the model in OpenSim 4 and save it "
                     "again to convert it");
    }
  }

  void read_model_properties(const XMLElement& model) {
    model_.name = name_of(model);
    model_.credits = text_or(model, "credits");
    model_.publications = text_or(model, "publications");
    model_.length_units = text_or(model, "length_units");
    model_.force_units = text_or(model, "force_units");
    model_.gravity = vec3_or(model, "gravity", model_.gravity);
  }

  // ------------------------------------------------------------ bodies

  void add_body(Body body, const XMLElement& element) {
    if (body.name.empty()) fail(element, "has no name attribute; every body needs a name");
    if (!body_names_.insert(body.name).second) {
      fail(element, "body name '" + body.name + "' is used twice; body names must be unique");
    }
    model_.bodies.push_back(std::move(body));
  }

  void read_wrap_objects(const XMLElement& owner, Body& body) const {
    for_each_object(owner.FirstChildElement("WrapObjectSet"), [&](const XMLElement& element) {
      WrapObject wrap;
      wrap.name = name_of(element);
      wrap.type = element.Name();
      wrap.body = body.name;
      wrap.xyz_body_rotation = vec3_or(element, "xyz_body_rotation", wrap.xyz_body_rotation);
      wrap.translation = vec3_or(element, "translation", wrap.translation);
      const std::string quadrant = text_or(element, "quadrant");
      if (!quadrant.empty() && ascii_lower(quadrant) != "unassigned") wrap.quadrant = quadrant;
      wrap.active = boolean_or(element, "active", true);
      if (wrap.type == "WrapSphere") {
        wrap.shape = WrapShape::kSphere;
        wrap.radius = scalar_or(element, "radius", 0.0);
      } else if (wrap.type == "WrapCylinder") {
        wrap.shape = WrapShape::kCylinder;
        wrap.radius = scalar_or(element, "radius", 0.0);
        wrap.length = scalar_or(element, "length", 0.0);
      } else if (wrap.type == "WrapEllipsoid") {
        wrap.shape = WrapShape::kEllipsoid;
        wrap.dimensions = vec3_or(element, "dimensions", wrap.dimensions);
      } else if (wrap.type == "WrapTorus") {
        wrap.shape = WrapShape::kTorus;
        wrap.inner_radius = scalar_or(element, "inner_radius", 0.0);
        wrap.outer_radius = scalar_or(element, "outer_radius", 0.0);
      }
      body.wrap_objects.push_back(std::move(wrap));
    });
  }

  void read_attached_geometry_4(const XMLElement& owner, Body& body) const {
    for_each_child(owner.FirstChildElement("attached_geometry"), [&](const XMLElement& element) {
      if (std::string_view(element.Name()) != "Mesh") return;  // analytic shapes: no file
      AttachedMesh mesh;
      mesh.name = name_of(element);
      mesh.mesh_file = text_or(element, "mesh_file");
      if (mesh.mesh_file.empty()) {
        fail(element, "has no <mesh_file>; expected the file name of the mesh (e.g. femur.vtp)");
      }
      mesh.scale_factors = vec3_or(element, "scale_factors", mesh.scale_factors);
      const std::string frame = last_segment(text_or(element, "socket_frame"));
      mesh.frame = frame.empty() ? body.name : frame;
      body.geometry.push_back(std::move(mesh));
    });
  }

  void read_bodies_4(const XMLElement& model) {
    if (const XMLElement* ground = model.FirstChildElement("Ground")) {
      Body body;
      body.name = name_of(*ground);
      if (body.name.empty()) body.name = "ground";
      body.is_ground = true;
      read_attached_geometry_4(*ground, body);
      read_wrap_objects(*ground, body);
      add_body(std::move(body), *ground);
    } else {
      Body body;
      body.name = "ground";
      body.is_ground = true;
      add_body(std::move(body), model);
    }
    for_each_object(model.FirstChildElement("BodySet"), [&](const XMLElement& element) {
      Body body;
      body.name = name_of(element);
      body.mass = scalar_or(element, "mass", 0.0);
      body.mass_center = vec3_or(element, "mass_center", body.mass_center);
      if (const XMLElement* inertia = element.FirstChildElement("inertia")) {
        const std::vector<double> v = numbers(*inertia, 6, "Ixx Iyy Izz Ixy Ixz Iyz");
        std::copy(v.begin(), v.end(), body.inertia.begin());
      }
      read_attached_geometry_4(element, body);
      read_wrap_objects(element, body);
      add_body(std::move(body), element);
    });
  }

  // 3.x: <VisibleObject> with <GeometrySet><objects><DisplayGeometry> or a
  // <geometry_files> list; the VisibleObject's scale_factors apply to all.
  void read_visible_object_3(const XMLElement& element, Body& body) const {
    const XMLElement* visible = element.FirstChildElement("VisibleObject");
    if (visible == nullptr) return;
    const Eigen::Vector3d scale = vec3_or(*visible, "scale_factors", Eigen::Vector3d::Ones());
    const std::string files = text_or(*visible, "geometry_files");
    for (const std::string_view file : split_xml_words(files)) {
      AttachedMesh mesh;
      mesh.name = std::string(file);
      mesh.mesh_file = std::string(file);
      mesh.scale_factors = scale;
      mesh.frame = body.name;
      body.geometry.push_back(std::move(mesh));
    }
    for_each_object(visible->FirstChildElement("GeometrySet"), [&](const XMLElement& display) {
      AttachedMesh mesh;
      mesh.mesh_file = text_or(display, "geometry_file");
      if (mesh.mesh_file.empty()) return;
      mesh.name = name_of(display).empty() ? mesh.mesh_file : name_of(display);
      mesh.scale_factors =
          scale.cwiseProduct(vec3_or(display, "scale_factors", Eigen::Vector3d::Ones()));
      mesh.frame = body.name;
      body.geometry.push_back(std::move(mesh));
    });
  }

  void read_bodies_and_joints_3(const XMLElement& model) {
    std::vector<std::pair<const XMLElement*, std::string>> joint_elements;
    for_each_object(model.FirstChildElement("BodySet"), [&](const XMLElement& element) {
      Body body;
      body.name = name_of(element);
      body.is_ground = body.name == "ground";
      body.mass = scalar_or(element, "mass", 0.0);
      body.mass_center = vec3_or(element, "mass_center", body.mass_center);
      constexpr std::array<const char*, 6> kInertia = {"inertia_xx", "inertia_yy", "inertia_zz",
                                                       "inertia_xy", "inertia_xz", "inertia_yz"};
      for (std::size_t i = 0; i < kInertia.size(); ++i) {
        body.inertia[i] = scalar_or(element, kInertia[i], 0.0);
      }
      read_visible_object_3(element, body);
      read_wrap_objects(element, body);
      if (const XMLElement* holder = element.FirstChildElement("Joint")) {
        if (const XMLElement* joint = holder->FirstChildElement()) {
          joint_elements.emplace_back(joint, body.name);
        }
      }
      add_body(std::move(body), element);
    });
    if (model_.bodies.empty()) {
      fail(model, "has no bodies in <BodySet><objects>; expected at least the ground body");
    }
    for (const auto& [element, child_body] : joint_elements) {
      Joint joint;
      joint.name = name_of(*element);
      joint.type = element->Name();
      const std::string parent_body = text_or(*element, "parent_body");
      const XMLElement* parent_body_element = element->FirstChildElement("parent_body");
      if (parent_body.empty() || parent_body_element == nullptr) {
        fail(*element, "has no <parent_body>; expected the name of the parent body (3.x layout)");
      }
      joint.parent = body_frame_3(*parent_body_element, parent_body);
      joint.parent.translation = vec3_or(*element, "location_in_parent", Eigen::Vector3d::Zero());
      joint.parent.orientation =
          vec3_or(*element, "orientation_in_parent", Eigen::Vector3d::Zero());
      joint.child.name = child_body;
      joint.child.body = child_body;
      joint.child.translation = vec3_or(*element, "location", Eigen::Vector3d::Zero());
      joint.child.orientation = vec3_or(*element, "orientation", Eigen::Vector3d::Zero());
      for_each_object(element->FirstChildElement("CoordinateSet"),
                      [&](const XMLElement& coordinate) { read_coordinate(coordinate, joint); });
      read_spatial_transform(*element, joint);
      add_joint(std::move(joint), *element);
    }
  }

  FrameRef body_frame_3(const XMLElement& where, const std::string& body) const {
    if (!body_names_.contains(body)) {
      fail(where, "refers to body " + quote_for_message(body) +
                      ", which the model does not define; " + known_bodies());
    }
    return body_frame(body);
  }

  std::string known_bodies() const {
    std::string list = "bodies are:";
    for (const Body& body : model_.bodies) list += " " + body.name;
    return list;
  }

  // ------------------------------------------------------------ frames (4.x)

  void collect_offset_frames(const XMLElement& model) {
    const auto add_frames = [&](const XMLElement* holder, OffsetFrameEntry::Scope scope,
                                const std::string& owner) {
      for_each_child(holder, [&](const XMLElement& element) {
        if (element.FirstChildElement("socket_parent") == nullptr) return;  // not an offset frame
        offset_frames_.push_back({&element, name_of(element), scope, owner});
      });
    };
    for_each_object(model.FirstChildElement("BodySet"), [&](const XMLElement& body) {
      add_frames(body.FirstChildElement("components"), OffsetFrameEntry::Scope::kBody,
                 name_of(body));
    });
    for_each_object(model.FirstChildElement("JointSet"), [&](const XMLElement& joint) {
      declared_joints_.insert(name_of(joint));
      add_frames(joint.FirstChildElement("frames"), OffsetFrameEntry::Scope::kJoint,
                 name_of(joint));
    });
    add_frames(model.FirstChildElement("components"), OffsetFrameEntry::Scope::kModel, "");
    if (const XMLElement* component_set = model.FirstChildElement("ComponentSet")) {
      add_frames(component_set->FirstChildElement("objects"), OffsetFrameEntry::Scope::kModel, "");
    }
  }

  const OffsetFrameEntry* find_offset_frame(std::string_view name, OffsetFrameEntry::Scope scope,
                                            std::string_view owner) const {
    for (const OffsetFrameEntry& entry : offset_frames_) {
      if (entry.name == name && entry.scope == scope && entry.owner == owner) return &entry;
    }
    return nullptr;
  }

  bool is_joint_name(std::string_view name) const { return declared_joints_.contains(name); }

  // Resolves a socket path (as written in `where`) to a body and an offset
  // from it. `context_joint` is the joint whose own frames a bare name may
  // refer to.
  FrameRef resolve_frame(const XMLElement& where, std::string_view path,
                         std::string_view context_joint, int depth) const {
    if (depth > kMaxFrameDepth) {
      fail(where, "offset frames refer to each other in a cycle (via " + quote_for_message(path) +
                      "); each PhysicalOffsetFrame must end at a body");
    }
    const std::vector<std::string_view> segments = split_path(path);
    if (segments.empty()) {
      fail(where, "names no frame (" + quote_for_message(path) +
                      "); expected a frame path such as /bodyset/femur_r");
    }
    const std::string name(segments.back());
    const std::string_view scope = segments.size() >= 2 ? segments[segments.size() - 2] : "";
    using Scope = OffsetFrameEntry::Scope;
    const OffsetFrameEntry* entry = nullptr;
    if (scope == "bodyset") {
      if (!body_names_.contains(name)) {
        fail(where, "refers to " + quote_for_message(path) + ", but the model has no body " +
                        quote_for_message(name) + "; " + known_bodies());
      }
      return body_frame(name);
    }
    if (!scope.empty() && is_joint_name(scope)) {
      entry = find_offset_frame(name, Scope::kJoint, scope);
    } else if (!scope.empty() && body_names_.contains(scope)) {
      entry = find_offset_frame(name, Scope::kBody, scope);
    } else {
      // A bare name ("pelvis_offset", "/ground"): the joint's own frames
      // first, then the bodies, then model-level and unique named frames.
      if (!context_joint.empty()) entry = find_offset_frame(name, Scope::kJoint, context_joint);
      if (entry == nullptr && body_names_.contains(name)) return body_frame(name);
      if (entry == nullptr) entry = find_offset_frame(name, Scope::kModel, "");
      if (entry == nullptr) entry = unique_offset_frame(where, name);
    }
    if (entry == nullptr) {
      fail(where, "refers to frame " + quote_for_message(path) +
                      ", which is neither a body nor a PhysicalOffsetFrame of the model; " +
                      known_bodies());
    }
    const XMLElement& socket = required(*entry->element, "socket_parent",
                                        "expected the path of the frame it is offset from");
    const std::string_view joint_scope =
        entry->scope == Scope::kJoint ? std::string_view(entry->owner) : std::string_view();
    const FrameRef parent =
        resolve_frame(socket, trim_xml_space(text_of(socket)), joint_scope, depth + 1);
    const Eigen::Vector3d translation =
        vec3_or(*entry->element, "translation", Eigen::Vector3d::Zero());
    const Eigen::Vector3d orientation =
        vec3_or(*entry->element, "orientation", Eigen::Vector3d::Zero());
    FrameRef frame;
    frame.name = name;
    frame.body = parent.body;
    if (parent.orientation.isZero(0.0)) {
      frame.translation = parent.translation + translation;
      frame.orientation = orientation;
    } else {
      const Eigen::Matrix3d rotation = parent.rotation();
      frame.translation = parent.translation + rotation * translation;
      frame.orientation = xyz_angles(rotation * rotation_xyz(orientation));
    }
    return frame;
  }

  static FrameRef body_frame(const std::string& body) {
    FrameRef frame;
    frame.name = body;
    frame.body = body;
    return frame;
  }

  const OffsetFrameEntry* unique_offset_frame(const XMLElement& where,
                                              const std::string& name) const {
    const OffsetFrameEntry* found = nullptr;
    for (const OffsetFrameEntry& entry : offset_frames_) {
      if (entry.name != name) continue;
      if (found != nullptr) {
        fail(where, "frame name " + quote_for_message(name) + " is ambiguous (owned by both '" +
                        found->owner + "' and '" + entry.owner +
                        "'); use the full path, e.g. /jointset/" + entry.owner + "/" + name);
      }
      found = &entry;
    }
    return found;
  }

  FrameRef socket_frame(const XMLElement& owner, const char* socket,
                        std::string_view context_joint) const {
    const XMLElement& element =
        required(owner, socket, "expected the path of its frame, e.g. /bodyset/femur_r");
    return resolve_frame(element, trim_xml_space(text_of(element)), context_joint, 0);
  }

  // Frame of a path point or marker: 4.x socket_parent_frame, 3.x <body>.
  FrameRef point_frame(const XMLElement& element) const {
    if (version_ >= kFirstVersion4 || element.FirstChildElement("socket_parent_frame") != nullptr) {
      return socket_frame(element, "socket_parent_frame", "");
    }
    const XMLElement& body = required(element, "body", "expected the name of its body");
    return body_frame_3(body, std::string(trim_xml_space(text_of(body))));
  }

  // ------------------------------------------------------------ joints

  void read_coordinate(const XMLElement& element, Joint& joint) {
    Coordinate coordinate;
    coordinate.name = name_of(element);
    if (coordinate.name.empty()) fail(element, "has no name attribute");
    coordinate.joint = joint.name;
    coordinate.default_value = scalar_or(element, "default_value", 0.0);
    coordinate.range = {-10.0, 10.0};  // OpenSim's default range
    if (const XMLElement* range = element.FirstChildElement("range")) {
      coordinate.range = range2(*range);
    }
    coordinate.clamped = boolean_or(element, "clamped", false);
    coordinate.locked = boolean_or(element, "locked", false);
    if (const XMLElement* motion = element.FirstChildElement("motion_type")) {
      const std::string type = ascii_lower(trim_xml_space(text_of(*motion)));
      if (type == "rotational") {
        coordinate.motion_type = MotionType::kRotational;
      } else if (type == "translational") {
        coordinate.motion_type = MotionType::kTranslational;
      } else if (type == "coupled") {
        coordinate.motion_type = MotionType::kCoupled;
      } else {
        fail(*motion, "holds " + quote_for_message(type) +
                          ", expected rotational, translational or coupled");
      }
      explicit_motion_types_.insert(coordinate.name);
    }
    joint.coordinates.push_back(std::move(coordinate));
  }

  // The function element of a TransformAxis: 3.x wraps it in <function>; 4.x
  // writes it directly with name="function".
  static const XMLElement* axis_function_element(const XMLElement& axis) {
    if (const XMLElement* wrapper = axis.FirstChildElement("function")) {
      return wrapper->FirstChildElement();
    }
    for (const XMLElement* child = axis.FirstChildElement(); child != nullptr;
         child = child->NextSiblingElement()) {
      const char* name = child->Attribute("name");
      if (name != nullptr && std::string_view(name) == "function") return child;
      if (is_function_tag(child->Name())) return child;
    }
    return nullptr;
  }

  Function read_function(const XMLElement& element) const {
    const std::string_view tag = element.Name();
    if (tag == "Constant") return Constant{scalar_or(element, "value", 0.0)};
    if (tag == "LinearFunction") {
      const XMLElement* coefficients = element.FirstChildElement("coefficients");
      if (coefficients == nullptr) return LinearFunction{};
      const std::vector<double> v = numbers(*coefficients, 2, "slope intercept");
      return LinearFunction{v[0], v[1]};
    }
    if (tag == "PolynomialFunction") {
      const XMLElement* coefficients = element.FirstChildElement("coefficients");
      return PolynomialFunction{coefficients != nullptr ? numbers(*coefficients)
                                                        : std::vector<double>{}};
    }
    if (tag == "SimmSpline" || tag == "PiecewiseLinearFunction") {
      const XMLElement& x = required(element, "x", "expected the x values of the points");
      const XMLElement& y = required(element, "y", "expected the y values of the points");
      try {
        if (tag == "SimmSpline") return SimmSpline(numbers(x), numbers(y));
        return PiecewiseLinearFunction(numbers(x), numbers(y));
      } catch (const InvalidInputError& error) {
        fail(element, error.what());
      }
    }
    if (tag == "MultiplierFunction") {
      const XMLElement& wrapper =
          required(element, "function", "expected <function> holding the scaled function");
      const XMLElement* inner = wrapper.FirstChildElement();
      if (inner == nullptr) fail(wrapper, "is empty; expected one function element inside");
      return MultiplierFunction(read_function(*inner), scalar_or(element, "scale", 1.0));
    }
    fail(element, "function type " + quote_for_message(tag) +
                      " is not supported; expected one of " + std::string(kSupportedFunctions) +
                      " (hint: refit the curve as a SimmSpline in OpenSim)");
  }

  // The function inside a holder element such as <x_location> (4.x) or
  // <XAttachment>: its first child element, skipping a <function> wrapper.
  Function read_held_function(const XMLElement& holder) const {
    const XMLElement* element = holder.FirstChildElement();
    if (element != nullptr && std::string_view(element->Name()) == "function") {
      element = element->FirstChildElement();
    }
    if (element == nullptr) {
      fail(holder,
           "is empty; expected a function element (" + std::string(kSupportedFunctions) + ")");
    }
    return read_function(*element);
  }

  void read_spatial_transform(const XMLElement& element, Joint& joint) {
    const XMLElement* transform = element.FirstChildElement("SpatialTransform");
    if (transform == nullptr) {
      if (joint.type == "CustomJoint") {
        fail(element, "CustomJoint has no <SpatialTransform>; expected 6 TransformAxis elements");
      }
      return;
    }
    for (const XMLElement* axis = transform->FirstChildElement("TransformAxis"); axis != nullptr;
         axis = axis->NextSiblingElement("TransformAxis")) {
      TransformAxis transform_axis;
      transform_axis.name = name_of(*axis);
      const std::string coordinate_list = text_or(*axis, "coordinates");
      for (const std::string_view word : split_xml_words(coordinate_list)) {
        transform_axis.coordinates.emplace_back(word);
      }
      transform_axis.axis = vec3(required(*axis, "axis", "expected the axis direction 'x y z'"));
      if (transform_axis.axis.norm() == 0.0) {
        fail(required(*axis, "axis", ""), "is the zero vector; expected a direction");
      }
      if (const XMLElement* function = axis_function_element(*axis)) {
        transform_axis.function = read_function(*function);
      } else if (!transform_axis.coordinates.empty()) {
        fail(*axis, "uses coordinate '" + transform_axis.coordinates.front() +
                        "' but has no function; expected e.g. <LinearFunction name=\"function\">"
                        "<coefficients>1 0</coefficients></LinearFunction>");
      }
      // OpenSim adds coordinates that only the transform names.
      for (const std::string& name : transform_axis.coordinates) {
        const bool known = std::any_of(joint.coordinates.begin(), joint.coordinates.end(),
                                       [&](const Coordinate& c) { return c.name == name; });
        if (!known) {
          Coordinate coordinate;
          coordinate.name = name;
          coordinate.joint = joint.name;
          coordinate.range = {-10.0, 10.0};
          joint.coordinates.push_back(std::move(coordinate));
        }
      }
      joint.spatial_transform.push_back(std::move(transform_axis));
    }
    if (joint.spatial_transform.size() != 6) {
      fail(*transform, "holds " + std::to_string(joint.spatial_transform.size()) +
                           " TransformAxis elements, expected 6 (rotation1..3, translation1..3)");
    }
  }

  void add_joint(Joint joint, const XMLElement& element) {
    if (joint.name.empty()) fail(element, "has no name attribute; every joint needs a name");
    if (!joint_names_.insert(joint.name).second) {
      fail(element, "joint name '" + joint.name + "' is used twice; joint names must be unique");
    }
    for (const Coordinate& coordinate : joint.coordinates) {
      if (!coordinate_names_.insert(coordinate.name).second) {
        fail(element, "coordinate '" + coordinate.name +
                          "' is defined twice in the model; coordinate names must be unique");
      }
    }
    model_.joints.push_back(std::move(joint));
  }

  void read_joints_4(const XMLElement& model) {
    for_each_object(model.FirstChildElement("JointSet"), [&](const XMLElement& element) {
      Joint joint;
      joint.name = name_of(element);
      joint.type = element.Name();
      joint.parent = socket_frame(element, "socket_parent_frame", joint.name);
      joint.child = socket_frame(element, "socket_child_frame", joint.name);
      if (const XMLElement* coordinates = element.FirstChildElement("coordinates")) {
        for_each_child(coordinates,
                       [&](const XMLElement& coordinate) { read_coordinate(coordinate, joint); });
      }
      read_spatial_transform(element, joint);
      add_joint(std::move(joint), element);
    });
  }

  void finish_joints() {
    for (Joint& joint : model_.joints) {
      const std::vector<MotionType> by_type = motion_types_of_joint_type(joint.type);
      for (std::size_t i = 0; i < joint.coordinates.size(); ++i) {
        Coordinate& coordinate = joint.coordinates[i];
        if (explicit_motion_types_.contains(coordinate.name)) continue;
        if (!joint.spatial_transform.empty()) {
          coordinate.motion_type = MotionType::kCoupled;
          for (const bool rotation : {true, false}) {
            const std::size_t first = rotation ? 0 : 3;
            for (std::size_t a = first; a < first + 3 && a < joint.spatial_transform.size(); ++a) {
              const TransformAxis& axis = joint.spatial_transform[a];
              const bool uses = std::find(axis.coordinates.begin(), axis.coordinates.end(),
                                          coordinate.name) != axis.coordinates.end();
              if (uses && is_unit_slope(axis.function) &&
                  coordinate.motion_type == MotionType::kCoupled) {
                coordinate.motion_type = motion_type_of_axis_use(rotation);
              }
            }
          }
        } else if (i < by_type.size()) {
          coordinate.motion_type = by_type[i];
        }
      }
    }
  }

  // ------------------------------------------------------------ markers

  void read_markers(const XMLElement& model) {
    std::set<std::string> names;
    for_each_object(model.FirstChildElement("MarkerSet"), [&](const XMLElement& element) {
      Marker marker;
      marker.name = name_of(element);
      if (!names.insert(marker.name).second) {
        fail(element, "marker name '" + marker.name + "' is used twice");
      }
      marker.frame = point_frame(element);
      marker.location = vec3_or(element, "location", marker.location);
      marker.fixed = boolean_or(element, "fixed", false);
      model_.markers.push_back(std::move(marker));
    });
  }

  // ------------------------------------------------------------ forces

  std::string coordinate_reference(const XMLElement& element) const {
    std::string name = last_segment(trim_xml_space(text_of(element)));
    if (!coordinate_names_.contains(name)) {
      fail(element, "refers to coordinate " + quote_for_message(trim_xml_space(text_of(element))) +
                        ", which no joint of the model defines");
    }
    return name;
  }

  // Moving-point function and its coordinate for one axis ('x', 'y', 'z').
  void read_moving_axis(const XMLElement& element, char axis, Function& function,
                        std::string& coordinate) const {
    const std::string prefix(1, axis);
    const std::string location_tag = prefix + "_location";
    const std::string attachment_tag =
        std::string(1, static_cast<char>(axis - 'a' + 'A')) + "Attachment";
    const XMLElement* holder = element.FirstChildElement(location_tag.c_str());
    if (holder == nullptr) holder = element.FirstChildElement(attachment_tag.c_str());
    if (holder == nullptr) {
      fail(element, "has no <" + location_tag +
                        ">; a MovingPathPoint needs x_location, "
                        "y_location and z_location functions");
    }
    function = read_held_function(*holder);
    const std::string socket_tag = "socket_" + prefix + "_coordinate";
    const std::string coordinate_tag = prefix + "_coordinate";
    const XMLElement* reference = element.FirstChildElement(socket_tag.c_str());
    if (reference == nullptr) reference = element.FirstChildElement(coordinate_tag.c_str());
    if (reference == nullptr) {
      fail(element, "has no <" + socket_tag + ">; expected the coordinate driving " + location_tag);
    }
    coordinate = coordinate_reference(*reference);
  }

  double default_value_of(const std::string& coordinate) const {
    const Coordinate* found = model_.find_coordinate(coordinate);
    return found != nullptr ? found->default_value : 0.0;
  }

  PathPoint read_path_point(const XMLElement& element) const {
    PathPoint point;
    point.name = name_of(element);
    const std::string_view tag = element.Name();
    point.frame = point_frame(element);
    point.location = vec3_or(element, "location", point.location);
    if (tag == "ConditionalPathPoint") {
      point.kind = PathPointKind::kConditional;
      const XMLElement* reference = element.FirstChildElement("socket_coordinate");
      if (reference == nullptr) reference = element.FirstChildElement("coordinate");
      if (reference == nullptr) {
        fail(element,
             "has no <socket_coordinate>; expected the coordinate whose range "
             "switches the point on");
      }
      point.coordinate = coordinate_reference(*reference);
      if (const XMLElement* range = element.FirstChildElement("range")) {
        point.range = range2(*range);
      }
    } else if (tag == "MovingPathPoint") {
      point.kind = PathPointKind::kMoving;
      read_moving_axis(element, 'x', point.x_location, point.x_coordinate);
      read_moving_axis(element, 'y', point.y_location, point.y_coordinate);
      read_moving_axis(element, 'z', point.z_location, point.z_coordinate);
      point.location = {point.x_location.evaluate(default_value_of(point.x_coordinate)),
                        point.y_location.evaluate(default_value_of(point.y_coordinate)),
                        point.z_location.evaluate(default_value_of(point.z_coordinate))};
    } else if (tag != "PathPoint") {
      fail(element,
           "is not a path point type this reader knows; expected PathPoint, "
           "ConditionalPathPoint or MovingPathPoint");
    }
    return point;
  }

  void read_path_wraps(const XMLElement& path, Muscle& muscle) const {
    for_each_object(path.FirstChildElement("PathWrapSet"), [&](const XMLElement& element) {
      PathWrap wrap;
      wrap.name = name_of(element);
      const XMLElement& object =
          required(element, "wrap_object", "expected the name of a wrap object of a body");
      wrap.wrap_object = std::string(trim_xml_space(text_of(object)));
      if (model_.find_wrap_object(wrap.wrap_object) == nullptr) {
        fail(object, "refers to wrap object " + quote_for_message(wrap.wrap_object) +
                         ", which no body's WrapObjectSet defines");
      }
      const std::string method = text_or(element, "method");
      if (!method.empty()) wrap.method = method;
      if (const XMLElement* range = element.FirstChildElement("range")) {
        const std::vector<double> v = numbers(*range, 2, "first last path point, -1 for all");
        for (std::size_t i = 0; i < 2; ++i) {
          if (v[i] != std::floor(v[i])) {
            fail(*range, "value " + std::to_string(v[i]) + " is not an integer point index");
          }
          wrap.range[i] = static_cast<int>(v[i]);
        }
      }
      muscle.path_wraps.push_back(std::move(wrap));
    });
  }

  void read_forces(const XMLElement& model) {
    std::set<std::string> names;
    for_each_object(model.FirstChildElement("ForceSet"), [&](const XMLElement& element) {
      const XMLElement* path = element.FirstChildElement("GeometryPath");
      if (path == nullptr) return;  // not a path force
      Muscle muscle;
      muscle.name = name_of(element);
      muscle.type = element.Name();
      if (!names.insert(muscle.name).second) {
        fail(element, "force name '" + muscle.name + "' is used twice; names must be unique");
      }
      if (element.FirstChildElement("appliesForce") != nullptr) {
        muscle.applies_force = boolean_or(element, "appliesForce", true);
      } else {
        muscle.applies_force = !boolean_or(element, "isDisabled", false);
      }
      muscle.has_muscle_parameters = element.FirstChildElement("max_isometric_force") != nullptr;
      muscle.max_isometric_force = scalar_or(element, "max_isometric_force", 0.0);
      muscle.optimal_fiber_length = scalar_or(element, "optimal_fiber_length", 0.0);
      muscle.tendon_slack_length = scalar_or(element, "tendon_slack_length", 0.0);
      muscle.pennation_angle_at_optimal =
          element.FirstChildElement("pennation_angle_at_optimal") != nullptr
              ? scalar_or(element, "pennation_angle_at_optimal", 0.0)
              : scalar_or(element, "pennation_angle", 0.0);
      for_each_object(path->FirstChildElement("PathPointSet"), [&](const XMLElement& point) {
        muscle.path_points.push_back(read_path_point(point));
      });
      if (muscle.path_points.size() < 2) {
        fail(*path, "has " + std::to_string(muscle.path_points.size()) +
                        " path points, expected at least 2 (origin and insertion)");
      }
      read_path_wraps(*path, muscle);
      model_.muscles.push_back(std::move(muscle));
    });
  }

  std::string_view xml_;
  std::filesystem::path path_;
  tinyxml2::XMLDocument document_;
  int version_ = 0;
  OsimModel model_;
  std::set<std::string, std::less<>> body_names_;
  std::set<std::string, std::less<>> joint_names_;
  std::set<std::string, std::less<>> coordinate_names_;
  std::set<std::string, std::less<>> explicit_motion_types_;
  std::vector<OffsetFrameEntry> offset_frames_;
  std::set<std::string, std::less<>> declared_joints_;  // 4.x JointSet names, for frame paths
};

std::string read_file(const std::filesystem::path& file) {
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (error || !std::filesystem::exists(status)) {
    throw IoError(file, "no such file (check the path; OpenSim models end in .osim)");
  }
  if (std::filesystem::is_directory(status)) {
    throw IoError(file, "is a directory, not an .osim file");
  }
  std::ifstream stream(file, std::ios::binary);
  if (!stream) throw IoError(file, "cannot be opened for reading (permissions?)");
  std::string data((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  if (stream.bad()) throw IoError(file, "read error");
  if (data.empty()) throw IoError(file, "file is empty; expected OpenSim model XML");
  return data;
}

template <typename T>
const T* find_named(const std::vector<T>& items, std::string_view name) {
  const auto it =
      std::find_if(items.begin(), items.end(), [&](const T& item) { return item.name == name; });
  return it != items.end() ? &*it : nullptr;
}

}  // namespace

Eigen::Matrix3d rotation_xyz(const Eigen::Vector3d& angles) {
  const Eigen::Matrix3d rx = Eigen::AngleAxisd(angles.x(), Eigen::Vector3d::UnitX()).matrix();
  const Eigen::Matrix3d ry = Eigen::AngleAxisd(angles.y(), Eigen::Vector3d::UnitY()).matrix();
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(angles.z(), Eigen::Vector3d::UnitZ()).matrix();
  return rx * ry * rz;
}

Eigen::Matrix3d FrameRef::rotation() const { return rotation_xyz(orientation); }

Eigen::Vector3d FrameRef::to_body(const Eigen::Vector3d& point) const {
  return translation + rotation() * point;
}

const Body* OsimModel::find_body(std::string_view body_name) const {
  return find_named(bodies, body_name);
}

const Joint* OsimModel::find_joint(std::string_view joint_name) const {
  return find_named(joints, joint_name);
}

const Muscle* OsimModel::find_muscle(std::string_view muscle_name) const {
  return find_named(muscles, muscle_name);
}

const Marker* OsimModel::find_marker(std::string_view marker_name) const {
  return find_named(markers, marker_name);
}

const Coordinate* OsimModel::find_coordinate(std::string_view coordinate_name) const {
  for (const Joint& joint : joints) {
    if (const Coordinate* found = find_named(joint.coordinates, coordinate_name)) return found;
  }
  return nullptr;
}

const WrapObject* OsimModel::find_wrap_object(std::string_view wrap_name) const {
  for (const Body& body : bodies) {
    if (const WrapObject* found = find_named(body.wrap_objects, wrap_name)) return found;
  }
  return nullptr;
}

OsimModel parse_osim(std::string_view xml, const std::filesystem::path& name_for_messages) {
  return OsimReader(xml, name_for_messages).read();
}

OsimModel read_osim(const std::filesystem::path& file) {
  const std::string data = read_file(file);
  return parse_osim(data, file);
}

}  // namespace mmm::opensim
