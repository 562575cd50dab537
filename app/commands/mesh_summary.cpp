#include "app/commands/mesh_summary.h"

#include <cmath>
#include <sstream>

#include "nodes/mesh_check_json.h"

namespace mmm::app {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

std::string fmt(double value, int precision = 3) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(precision);
  out << value;
  return out.str();
}

std::string fmt(const Eigen::Vector3d& v, int precision = 3) {
  return fmt(v.x(), precision) + " " + fmt(v.y(), precision) + " " + fmt(v.z(), precision);
}

}  // namespace

MeshSummary summarize_mesh(const mesh::IndexedMesh& mesh, const std::filesystem::path& file) {
  MeshSummary summary;
  summary.file = file;
  summary.check = mesh::check_mesh(mesh);
  summary.properties = mesh::mass_properties(mesh);
  summary.bounds = mesh::bounding_box(mesh);
  summary.oriented_box = mesh::oriented_bounding_box(mesh);
  return summary;
}

nlohmann::json to_json(const MeshSummary& s, const std::string& units) {
  const mesh::MeshCheckReport& c = s.check;
  nlohmann::json out;
  out["file"] = s.file.string();
  out["units"] = units;
  out["vertices"] = c.vertices;
  out["faces"] = c.faces;
  out["closed"] = c.closed();
  out["watertight"] = c.watertight();
  out["check"] = nodes::mesh_check_json(c);
  // Volume is null when it is not a property of the shape (open surface).
  out["volume"] = s.has_volume() ? nlohmann::json(s.properties.volume) : nlohmann::json();
  out["outward_oriented"] = s.outward();
  out["area"] = s.properties.area;
  out["centroid"] = vec(s.properties.centroid);
  out["centroid_of"] = s.has_volume() ? "solid" : "surface";
  out["bounding_box"] = {
      {"min", vec(s.bounds.min())}, {"max", vec(s.bounds.max())}, {"size", vec(s.bounds.sizes())}};
  const mesh::OrientedBox& box = s.oriented_box;
  out["oriented_box"] = {
      {"center", vec(box.center)},
      {"axes", {vec(box.axes.col(0)), vec(box.axes.col(1)), vec(box.axes.col(2))}},
      {"half_extents", vec(box.half_extents)}};
  return out;
}

std::string to_text(const MeshSummary& s, const std::string& units) {
  const mesh::MeshCheckReport& c = s.check;
  const std::string u2 = units + "^2";
  const std::string u3 = units + "^3";
  std::ostringstream out;
  out << "file        " << s.file.string() << '\n';
  out << "size        " << c.vertices << " vertices, " << c.faces << " faces, " << c.edges
      << " edges, " << c.connected_components << " component(s), Euler characteristic "
      << c.euler_characteristic << '\n';
  out << "closed      " << (c.closed() ? "yes" : "no")
      << "  (watertight: " << (c.watertight() ? "yes" : "no") << ")\n";
  const auto problems = c.problems();
  if (problems.empty()) {
    out << "problems    none\n";
  } else {
    for (size_t i = 0; i < problems.size(); ++i) {
      out << (i == 0 ? "problems    " : "            ") << problems[i] << '\n';
    }
  }
  if (s.has_volume()) {
    out << "volume      " << fmt(s.properties.volume, 1) << ' ' << u3
        << (s.outward() ? "" : "  (faces point inward)") << '\n';
  } else {
    out << "volume      n/a (the surface does not enclose a volume)\n";
  }
  out << "area        " << fmt(s.properties.area, 1) << ' ' << u2 << '\n';
  out << "centroid    " << fmt(s.properties.centroid) << ' ' << units << " (of the "
      << (s.has_volume() ? "solid" : "surface") << ")\n";
  out << "bbox min    " << fmt(s.bounds.min()) << ' ' << units << '\n';
  out << "bbox max    " << fmt(s.bounds.max()) << ' ' << units << '\n';
  out << "bbox size   " << fmt(s.bounds.sizes()) << ' ' << units << '\n';
  out << "long axis   " << fmt(s.oriented_box.axes.col(0)) << "  (oriented box "
      << fmt(2.0 * s.oriented_box.half_extents, 1) << ' ' << units << ")\n";
  return out.str();
}

}  // namespace mmm::app
