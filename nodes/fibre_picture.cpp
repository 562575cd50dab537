#include "nodes/fibre_picture.h"

#include <Eigen/Geometry>
#include <array>

#include "core/fibres/tube.h"
#include "core/image/mesh_render.h"

namespace mmm::nodes {
namespace {

using Eigen::Index;

constexpr double kTubeRadiusMm = 0.6;
constexpr int kTubeSides = 6;

// The faces of `muscle` whose outward normal points along `view`.
mesh::IndexedMesh far_wall(const mesh::IndexedMesh& muscle, const Eigen::Vector3d& view) {
  mesh::IndexedMesh wall{muscle.V, Eigen::MatrixX3i(muscle.F.rows(), 3)};
  Index kept = 0;
  for (Index f = 0; f < muscle.F.rows(); ++f) {
    const Eigen::Vector3d a = muscle.V.row(muscle.F(f, 0)).transpose();
    const Eigen::Vector3d b = muscle.V.row(muscle.F(f, 1)).transpose();
    const Eigen::Vector3d c = muscle.V.row(muscle.F(f, 2)).transpose();
    if ((b - a).cross(c - a).dot(view) > 0.0) wall.F.row(kept++) = muscle.F.row(f);
  }
  wall.F.conservativeResize(kept, 3);
  return wall;
}

// All fibres as one mesh of tubes.
mesh::IndexedMesh fibre_tubes(const std::vector<fibres::Fibre>& fibres) {
  std::vector<mesh::IndexedMesh> tubes;
  Index vertices = 0;
  Index faces = 0;
  for (const fibres::Fibre& fibre : fibres) {
    try {
      tubes.push_back(fibres::tube_mesh(fibre,
                                        Eigen::VectorXd::Constant(fibre.rows(), kTubeRadiusMm),
                                        fibres::rotation_minimising_frames(fibre), kTubeSides));
    } catch (const std::exception&) {
      continue;  // a fibre with repeated points is left out of the picture
    }
    vertices += tubes.back().V.rows();
    faces += tubes.back().F.rows();
  }
  mesh::IndexedMesh all{Eigen::MatrixX3d(vertices, 3), Eigen::MatrixX3i(faces, 3)};
  Index v = 0;
  Index f = 0;
  for (const mesh::IndexedMesh& tube : tubes) {
    all.V.middleRows(v, tube.V.rows()) = tube.V;
    all.F.middleRows(f, tube.F.rows()) = tube.F.array() + static_cast<int>(v);
    v += tube.V.rows();
    f += tube.F.rows();
  }
  return all;
}

}  // namespace

image::RgbImage8 fibre_picture(const mesh::IndexedMesh& muscle,
                               const std::vector<fibres::Fibre>& fibres, int width_px) {
  const mesh::IndexedMesh tubes = fibre_tubes(fibres);
  std::vector<image::RgbImage8> views;
  const std::array<Eigen::Vector3d, 2> directions = {Eigen::Vector3d(0, -1, 0),
                                                     Eigen::Vector3d(-1, 0, 0)};
  for (const Eigen::Vector3d& view : directions) {
    const mesh::IndexedMesh wall = far_wall(muscle, view);
    const std::array<image::RenderItem, 2> items = {image::RenderItem{&wall, {215, 170, 160}},
                                                    image::RenderItem{&tubes, {170, 30, 40}}};
    image::RenderOptions options;
    options.view_direction = view;
    options.image_width = width_px;
    options.outline = false;
    views.push_back(image::render_meshes(items, options));
  }
  return image::side_by_side(views);
}

}  // namespace mmm::nodes
