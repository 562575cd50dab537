#include "core/atlas/structure_build.h"

#include "core/atlas/bone_contacts.h"
#include "core/atlas/millimetres_text.h"
#include "core/errors.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"

namespace mmm::atlas {

std::vector<StructureBuildReport> add_structures(
    const AtlasRecipe& recipe,
    const std::function<mesh::IndexedMesh(const std::string& file, const std::string& field)>& read,
    const std::map<std::string, mesh::IndexedMesh>& bones, const StructureBuildOptions& options,
    Atlas& atlas, std::map<std::string, mesh::IndexedMesh>& surfaces) {
  std::vector<StructureBuildReport> reports;
  SurfaceDistances distances;  // a bone carrying several structures is measured once
  for (const RecipeStructure& source : recipe.structures) {
    const std::string what = std::string(structure_kind_name(source.kind)) + " " + source.name;
    mesh::IndexedMesh surface = read(source.file, "structures." + source.name + ".file");
    if (surface.F.rows() == 0) {
      throw InvalidInputError("atlas build: " + what + ": " + source.file + " has no faces");
    }
    const mesh::MeshCheckReport health = mesh::check_mesh(surface);
    StructureBuildReport report;
    report.name = source.name;
    report.kind = structure_kind_name(source.kind);
    report.faces = static_cast<int>(surface.F.rows());
    report.watertight = health.watertight();
    if (!report.watertight) {
      throw InvalidInputError("atlas build: " + what + ": " + source.file +
                              " is not a closed, consistently oriented surface (" +
                              std::to_string(health.boundary_edges) + " boundary edges, " +
                              std::to_string(health.non_manifold_edges) +
                              " non-manifold edges; `mmm mesh info FILE` shows where)");
    }
    report.volume_mm3 = mesh::mass_properties(surface).volume;
    if (report.volume_mm3 <= 0) {
      throw InvalidInputError("atlas build: " + what + ": " + source.file +
                              " is inside out (negative volume); flip its faces");
    }
    for (const std::string& bone : source.bones) {
      const NamedSurface carried{source.name, &surface};
      const NamedSurface carrier{bone, &bones.at(bone)};
      const BoneContact contact =
          contact_between(carried, distances.of(carried), carrier, distances.of(carrier));
      report.gap_mm.emplace_back(bone, contact.gap_mm);
      report.overlap_mm.emplace_back(bone, contact.overlap_mm);
      if (contact.gap_mm > options.max_gap_mm) {
        std::string message = "atlas build: ";
        message += what;
        message += " is ";
        message += millimetres_text(contact.gap_mm);
        message += " from its bone ";
        message += bone;
        message += " (at most ";
        message += millimetres_text(options.max_gap_mm);
        message += "): it would float away with it; check the file and the bone";
        throw InvalidInputError(message);
      }
    }
    Structure structure;
    structure.name = source.name;
    structure.kind = source.kind;
    structure.tags = source.tags;
    structure.bones = source.bones;
    atlas.structures.push_back(std::move(structure));
    for (Region& region : atlas.regions) {
      if (region.name == source.region) region.structures.push_back(source.name);
    }
    surfaces[source.name] = std::move(surface);
    reports.push_back(std::move(report));
  }
  return reports;
}

}  // namespace mmm::atlas
