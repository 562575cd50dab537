#pragma once
// Node `load_mesh`: a mesh file (STL, OBJ, PLY, OFF, VTP) -> a Mesh artifact
// in mm. The artifact is read in place by the reader of the chosen format
// (core/mesh/io/*.h), so no copy with an extension is needed.
//
//   input  file    File   the mesh file as given to the study (bytes only:
//                         the format comes from the `format` parameter, since
//                         an artifact has no file name)
//   param  format  enum   stl | obj | ply | off | vtp (default stl)
//   param  scale   number multiply coordinates to get mm (default 1, in
//                         [1e-4, 1e6]; 1000 for OpenSim geometry in metres)
//   output mesh    Mesh   binary little-endian PLY, double coordinates, mm

#include "workflow/node_context.h"
#include "workflow/node_spec.h"

namespace mmm::nodes {

struct LoadMesh {
  static workflow::NodeSpec spec();
  // Throws IoError when the file is not a readable mesh of that format.
  static void run(workflow::NodeContext& context);
};

}  // namespace mmm::nodes
