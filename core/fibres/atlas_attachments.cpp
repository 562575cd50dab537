#include "core/fibres/atlas_attachments.h"

#include <string>

#include "core/errors.h"

namespace mmm::fibres {
namespace {

using Eigen::Index;

AreaSamples sample_area(const std::string& muscle, const atlas::AttachmentArea& area,
                        const mesh::IndexedMesh& bone) {
  AreaSamples samples{area.bone, Eigen::MatrixX3d(4 * static_cast<Index>(area.faces.size()), 3),
                      area.area_mm2};
  Index row = 0;
  for (const int face : area.faces) {
    if (face < 0 || face >= bone.F.rows()) {
      throw InvalidInputError("muscle " + muscle + ": attachment face " + std::to_string(face) +
                              " is not a face of bone " + area.bone + " (" +
                              std::to_string(bone.F.rows()) +
                              " faces); rebuild the atlas's attachment areas");
    }
    Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      samples.points.row(row++) = bone.V.row(bone.F(face, c));
      centroid += bone.V.row(bone.F(face, c)) / 3.0;
    }
    samples.points.row(row++) = centroid;
  }
  return samples;
}

Eigen::MatrixX3d gather(const std::vector<AreaSamples>& areas,
                        const std::function<Eigen::Isometry3d(const std::string&)>& pose) {
  Index rows = 0;
  for (const AreaSamples& area : areas) {
    rows += area.points.rows();
  }
  Eigen::MatrixX3d points(rows, 3);
  Index row = 0;
  for (const AreaSamples& area : areas) {
    if (pose) {
      const Eigen::Isometry3d transform = pose(area.bone);
      points.middleRows(row, area.points.rows()) =
          (area.points * transform.linear().transpose()).rowwise() +
          transform.translation().transpose();
    } else {
      points.middleRows(row, area.points.rows()) = area.points;
    }
    row += area.points.rows();
  }
  return points;
}

}  // namespace

MuscleAttachmentSamples attachment_samples(
    const atlas::Muscle& muscle,
    const std::function<const mesh::IndexedMesh&(const std::string&)>& bone_surface) {
  if (muscle.origins.empty() || muscle.insertions.empty()) {
    throw InvalidInputError("muscle " + muscle.name + " has no " +
                            (muscle.origins.empty() ? "origin" : "insertion") +
                            " attachment area; fibres need both (see the atlas recipe)");
  }
  MuscleAttachmentSamples samples;
  for (const atlas::AttachmentArea& area : muscle.origins) {
    samples.origin.push_back(sample_area(muscle.name, area, bone_surface(area.bone)));
  }
  for (const atlas::AttachmentArea& area : muscle.insertions) {
    samples.insertion.push_back(sample_area(muscle.name, area, bone_surface(area.bone)));
  }
  return samples;
}

Attachments posed_attachments(const MuscleAttachmentSamples& samples,
                              const std::function<Eigen::Isometry3d(const std::string&)>& pose) {
  Attachments attachments{gather(samples.origin, pose), gather(samples.insertion, pose), 0.0, 0.0};
  for (const AreaSamples& area : samples.origin) {
    attachments.origin_area_mm2 += area.area_mm2;
  }
  for (const AreaSamples& area : samples.insertion) {
    attachments.insertion_area_mm2 += area.area_mm2;
  }
  return attachments;
}

}  // namespace mmm::fibres
