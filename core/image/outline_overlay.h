#pragma once
// The operator's check picture after atlas scaling: the projected silhouette
// outlines of the (scaled) bones drawn in colour over the patient's
// calibrated radiographs, with optional landmark markers and a legend.
//
//   grey:      the 16-bit radiograph windowed to 8 bits: [low, high] -> [0, 255],
//              low/high the 1st/99th percentiles of the pixel values unless
//              given (one 65536-bin histogram, no sort)
//   silhouette (per mesh, per view; perspective from the X-ray focal spot s):
//              every face f gets the side s_f = sign(n_f . (c_f - s)), n_f its
//              (unnormalised) normal and c_f its centroid: < 0 front-facing,
//              > 0 back-facing as seen from the source; an edge is drawn when
//              its faces include a front- and a back-facing one (the contour
//              generator of a closed surface) or when it has one face only
//              (a boundary). Edges are found by sorting the 3 #F corner pairs.
//              Connected pieces of fewer than min_contour_edges edges (noise
//              of a coarse mesh turning edge-on) are dropped (union-find),
//              the mesh's largest piece never (silhouette.h: the same
//              edges, also as chained polylines).
//   lines:     each silhouette edge projected with the view's P and drawn
//              anti-aliased: a pixel whose centre lies at distance d from the
//              segment gets coverage clamp(w / 2 + 0.5 - d, 0, 1) (w the line
//              width), the maximum over the mesh's segments (so joints of the
//              polyline are not blended twice), then
//              pixel = (1 - coverage) pixel + coverage colour.
//   markers:   points projected the same way, as a '+' cross or a ring.
//   legend:    there is no font in mmm, so the legend is a column of colour
//              swatches in the items' order (top-left corner); callers print
//              or show the names beside the picture.
//
// The outline is the geometric contour of the mesh as the source sees it,
// occluded parts included (an X-ray shows every bone through every other):
// a bone behind another is outlined in full. Meshes must be consistently
// oriented: a flipped face makes a 3-edge loop of its own (dropped, like
// other small fragments, by min_contour_edges).
// Cost: O(#F log #F) per mesh plus the pixels of the lines, so a decimated
// level (about 4000 faces) is the right input; the windowing is O(pixels).

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/image/image.h"
#include "core/image/projection.h"
#include "core/image/radiograph_pair.h"
#include "core/mesh/mesh.h"

namespace mmm::image {

// One mesh to outline.
struct OutlineItem {
  std::string name;                         // shown by callers beside the legend
  const mesh::IndexedMesh* mesh = nullptr;  // not owned; V in mm, world (patient) frame
  Rgb8 colour{255, 64, 64};
};

enum class PointMarker { kCross, kCircle };

// A 3-D point to mark (e.g. an operator landmark, or the same landmark on the
// scaled atlas).
struct OverlayPoint {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();  // world (patient) frame
  Rgb8 colour{255, 255, 0};
  PointMarker marker = PointMarker::kCross;
};

struct OverlayOptions {
  // Grey window in raw sample values (0-65535): a value <= low is black,
  // >= high white. Each bound left empty is the percentile below of the
  // radiograph's own pixels (a robust window that ignores the few saturated
  // or dead pixels). When the bounds meet, high is taken as low + 1.
  std::optional<double> window_low;
  std::optional<double> window_high;
  double low_percentile = 1.0;    // in [0, 100), below high_percentile
  double high_percentile = 99.0;  // in (0, 100]
  // Width of outline and marker lines (pixels of the output image), in
  // (0, 20]. 1.5 px reads well at full and at half resolution.
  double line_width_px = 1.5;
  // Points to mark in every view (projected like the meshes; a point outside
  // the image is clipped).
  std::vector<OverlayPoint> points;
  // Connected pieces of a mesh's silhouette with fewer edges than this are
  // not drawn, unless no piece of that mesh is larger (a box's whole outline
  // has 4 to 6 edges): on a coarse mesh a face or two turned nearly edge-on
  // to the rays, against all their neighbours, close a loop of 3-6 edges
  // that shows as a dash inside the outline, while a bone's real contours at
  // lod1 (4000 faces) run over dozens of edges. 1 draws every silhouette edge.
  int min_contour_edges = 8;
  // Half the size of a cross / radius of a ring (pixels), in (0, 200].
  double marker_radius_px = 8.0;
  // Draw the legend: one swatch per item, in the items' order, top-left.
  bool legend = true;
  // outline_overlay_pair only: the side-by-side picture is scaled down
  // (area averaging, before the lines are drawn, so they stay sharp) to at
  // most this width (pixels, >= 64). Smaller pictures are never enlarged.
  int max_width = 2400;
  // outline_overlay_pair only: white columns between the views (pixels, >= 0).
  int gap_px = 10;
};

// The radiograph of `view` windowed to grey, with every item's silhouette
// outline (see the file comment) in its colour, the points and, when asked,
// the legend; width x height of the view. An empty item list gives the
// windowed radiograph (plus markers). Throws InvalidInputError naming what is
// wrong: a view failing validate_view, a radiograph whose size differs from
// the view's ("view 'frontal' is 1044 x 2757 pixels, the radiograph 1000 x
// 2757") or whose pixel count does not match its size, an item with a null
// mesh, a face index out of range, a non-finite coordinate or a vertex on or
// behind the source plane (the item is named), a non-finite point or one
// behind the source, options out of range.
RgbImage8 outline_overlay(const RadiographView& view, const GrayImage16& radiograph,
                          std::span<const OutlineItem> items, const OverlayOptions& options = {});

// Every view of the pair, in order, side by side (gap_px apart, top-aligned),
// each drawn as by outline_overlay, scaled down to at most max_width pixels
// wide; one legend for the whole picture. Throws what outline_overlay throws,
// and what RadiographPair::image throws for an image that cannot be decoded.
RgbImage8 outline_overlay_pair(const RadiographPair& pair, std::span<const OutlineItem> items,
                               const OverlayOptions& options = {});

// Distinct colours for `count` items (golden-angle hues, saturated and light
// enough to read on grey), for callers that colour many bones; none for
// count <= 0.
std::vector<Rgb8> distinct_colours(int count);

}  // namespace mmm::image
