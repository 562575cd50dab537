#include "nodes/registry.h"

#include "nodes/decimate_mesh.h"
#include "nodes/load_mesh.h"
#include "nodes/measure_mesh.h"

namespace mmm::nodes {

workflow::NodeRegistry make_node_registry() {
  workflow::NodeRegistry registry;
  registry.add<LoadMesh>();
  registry.add<DecimateMesh>();
  registry.add<MeasureMesh>();
  return registry;
}

}  // namespace mmm::nodes
