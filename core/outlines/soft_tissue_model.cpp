#include "core/outlines/soft_tissue_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "core/atlas/limb_envelope.h"
#include "core/errors.h"
#include "core/image/bilinear.h"
#include "core/image/drr.h"
#include "core/mesh/aabb_tree.h"
#include "core/outlines/bone_cover.h"

namespace mmm::outlines {
namespace {

// The view seen through pixels `factor` times larger (same source and field).
image::RadiographView coarse_view(const image::RadiographView& view, int factor) {
  image::RadiographView coarse = view;
  const double shrink = 1.0 / factor;
  coarse.P.row(0) *= shrink;
  coarse.P.row(1) *= shrink;
  coarse.width = (view.width + factor - 1) / factor;
  coarse.height = (view.height + factor - 1) / factor;
  coarse.pixel_spacing_mm = view.pixel_spacing_mm * factor;
  return coarse;
}

// Marks every pixel within `radius` pixels (a square) of a non-zero one.
std::vector<std::uint8_t> dilated(const std::vector<std::uint8_t>& mask, int width, int height,
                                  int radius) {
  const auto at = [width](int x, int y) {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  };
  std::vector<std::uint8_t> rows(mask.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (mask[at(x, y)] == 0) continue;
      for (int k = std::max(0, x - radius); k <= std::min(width - 1, x + radius); ++k) {
        rows[at(k, y)] = 1;
      }
    }
  }
  std::vector<std::uint8_t> out(mask.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (rows[at(x, y)] == 0) continue;
      for (int k = std::max(0, y - radius); k <= std::min(height - 1, y + radius); ++k) {
        out[at(x, k)] = 1;
      }
    }
  }
  return out;
}

double median_of(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::ranges::nth_element(values, middle);
  return *middle;
}

// The outermost edges of the limb in one row, in fine pixels (u).
struct RowEdges {
  bool found = false;
  double left = 0.0;
  double right = 0.0;
};

// Where the model's path length T leaves zero at either end of coarse row y:
// near a smooth silhouette T grows as c sqrt(distance), so the first two
// non-zero pixels place the edge.
RowEdges model_edges(const image::FloatImage& tissue, int y, int factor) {
  int first = -1;
  int last = -1;
  for (int x = 0; x < tissue.width; ++x) {
    if (tissue.at(x, y) <= 0) continue;
    if (first < 0) first = x;
    last = x;
  }
  RowEdges edges;
  if (first < 0 || last - first < 3) return edges;
  const auto edge = [&](int at, int inward) {
    const double t1 = tissue.at(at, y);
    const double t2 = tissue.at(at + inward, y);
    double back = 0.5;
    if (t2 > t1) back = std::clamp(t1 * t1 / (t2 * t2 - t1 * t1), 0.0, 1.0);
    return (at - inward * back + 0.5) * factor;
  };
  edges.found = true;
  edges.left = edge(first, 1);
  edges.right = edge(last, -1);
  return edges;
}

// Where the image first rises above `threshold` walking inward from `start`
// (fine pixels along row v, step 0.5 px, at most `span` px), refined between
// the two samples around the crossing; nothing if it never does.
std::optional<double> image_edge(const EdgeImage& image, double v, double start, double step,
                                 double span, double threshold) {
  start = std::clamp(start, 0.5, image.width() - 0.5);
  double previous_u = start;
  double previous = image.sample({start, v});
  if (previous > threshold) return std::nullopt;  // the limb (or another) reaches the start
  for (double walked = 0.5; walked <= span; walked += 0.5) {
    const double u = start + step * walked;
    if (u < 0 || u > image.width()) return std::nullopt;
    const double value = image.sample({u, v});
    if (value > threshold) {
      const double t = (threshold - previous) / (value - previous);
      const double crossing = previous_u + t * (u - previous_u);
      // The blur spreads the limb outward: the crossing lies about 2.3 sigma
      // outside the edge. The steepest fall, moved out by the sqrt law's
      // shift (edge_image.h), is the edge.
      const double sigma = image.sigma_px();
      const Eigen::Vector2d inward(crossing + step * 2.5 * sigma, v);
      const std::optional<EdgeImage::Edge> edge = image.edge_along(
          inward, {-step, 0.0}, 4.0 * sigma, std::max(1.0, 5.0 * image.median_gradient()));
      if (!edge) return crossing;
      return inward.x() - step * edge->offset_px;
    }
    previous_u = u;
    previous = value;
  }
  return std::nullopt;
}

// One view's coarse grid: the model's path lengths, the rows' outlines.
struct ViewGrid {
  image::RadiographView view;  // the coarse view
  int factor = 1;
  image::FloatImage tissue;  // mm in the envelope
  image::FloatImage muscle;  // mm in the muscles
  std::vector<RowEdges> model;
  std::vector<RowEdges> image;
  std::vector<double> ratio;  // the image's width over the model's per row; 0: unknown
  image::FloatImage warped_tissue;
  image::FloatImage warped_muscle;
  int rows_matched = 0;
  double median_ratio = 1.0;
};

// The limb's edges in the image against the model's, row by row. The image's
// air is the median of the pixels far from the model's limb; an edge is where
// the image first rises 30 units or 8 noise deviations above it, searched
// from `search_px` outside the model's edge inward (so another limb further
// out is not taken for this one).
void match_outline(ViewGrid& grid, const EdgeImage& image, double search_px) {
  const int width = grid.view.width;
  const int height = grid.view.height;
  const int far = std::max(1, static_cast<int>(std::ceil(search_px / grid.factor)));
  std::vector<std::uint8_t> limb(static_cast<std::size_t>(width) *
                                 static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) limb[grid.tissue.index(x, y)] = grid.tissue.at(x, y) > 0;
  }
  const std::vector<std::uint8_t> near = dilated(limb, width, height, far);
  std::vector<double> air;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (near[grid.tissue.index(x, y)] != 0) continue;
      air.push_back(image.sample({(x + 0.5) * grid.factor, (y + 0.5) * grid.factor}));
    }
  }
  grid.model.assign(static_cast<std::size_t>(height), {});
  grid.image.assign(static_cast<std::size_t>(height), {});
  grid.ratio.assign(static_cast<std::size_t>(height), 0.0);
  if (air.size() < 100) return;  // no air around the limb to judge its edge against
  const double level = median_of(air);
  for (double& value : air) value = std::abs(value - level);
  const double threshold = level + std::max(30.0, 8.0 * 1.4826 * median_of(air));
  std::vector<double> ratios;
  for (int y = 0; y < height; ++y) {
    const RowEdges model = model_edges(grid.tissue, y, grid.factor);
    if (!model.found) continue;
    const double v = (y + 0.5) * grid.factor;
    const double span = 2.0 * search_px;
    const std::optional<double> left =
        image_edge(image, v, model.left - search_px, 1.0, span, threshold);
    const std::optional<double> right =
        image_edge(image, v, model.right + search_px, -1.0, span, threshold);
    if (!left || !right || *right <= *left) continue;
    const double ratio = (*right - *left) / (model.right - model.left);
    if (ratio < 0.6 || ratio > 1.6) continue;  // another limb, a cut-off field: not this outline
    const auto row = static_cast<std::size_t>(y);
    grid.model[row] = model;
    grid.image[row] = {true, *left, *right};
    grid.ratio[row] = ratio;
    ratios.push_back(ratio);
  }
  grid.rows_matched = static_cast<int>(ratios.size());
  if (!ratios.empty()) grid.median_ratio = median_of(ratios);
}

// The envelope's centre line: the mean of its vertices in 2 mm slabs along z.
std::vector<Eigen::Vector3d> limb_axis(const mesh::IndexedMesh& envelope) {
  std::map<int, std::pair<Eigen::Vector3d, int>> slabs;
  for (Eigen::Index i = 0; i < envelope.V.rows(); ++i) {
    auto& [sum, count] = slabs[static_cast<int>(std::floor(envelope.V(i, 2) / 2.0))];
    if (count == 0) sum.setZero();
    sum += envelope.V.row(i).transpose();
    ++count;
  }
  std::vector<Eigen::Vector3d> axis;
  axis.reserve(slabs.size());
  for (const auto& [slab, mean] : slabs) axis.emplace_back(mean.first / mean.second);
  return axis;
}

// Row y of a grid at the height of the limb's axis point it shows there (the
// axis projected into the grid's view; rows between axis points interpolated),
// as a continuous row of `other`; nothing outside the axis.
std::optional<double> row_in_other(const ViewGrid& grid, const ViewGrid& other,
                                   const std::vector<Eigen::Vector3d>& axis, double y) {
  for (std::size_t i = 0; i + 1 < axis.size(); ++i) {
    const double a = image::project(grid.view, axis[i]).y() - 0.5;
    const double b = image::project(grid.view, axis[i + 1]).y() - 0.5;
    if ((y - a) * (y - b) > 0 || a == b) continue;
    const double t = (y - a) / (b - a);
    const double oa = image::project(other.view, axis[i]).y() - 0.5;
    const double ob = image::project(other.view, axis[i + 1]).y() - 0.5;
    return oa + t * (ob - oa);
  }
  return std::nullopt;
}

// The model's path lengths moved onto the image's outline: per row, stretched
// across so that its edges fall on the image's, and scaled by the other
// view's width ratio at that height (the slice's depth here). Rows without
// a matched outline keep the model as it is.
void warp_to_outline(ViewGrid& grid, const ViewGrid& other,
                     const std::vector<Eigen::Vector3d>& axis) {
  grid.warped_tissue = grid.tissue;
  grid.warped_muscle = grid.muscle;
  const auto along_row = [](const image::FloatImage& source, int y, double x) {
    if (x < 0 || x > source.width - 1) return 0.0;
    const int x0 = std::min(static_cast<int>(x), source.width - 2);
    const double t = x - x0;
    return (1 - t) * source.at(x0, y) + t * source.at(x0 + 1, y);
  };
  for (int y = 0; y < grid.view.height; ++y) {
    const auto row = static_cast<std::size_t>(y);
    if (grid.ratio[row] <= 0) continue;
    double depth = 1.0;
    if (const std::optional<double> there = row_in_other(grid, other, axis, y)) {
      const int below = static_cast<int>(std::floor(*there));
      const double t = *there - below;
      const auto ratio_at = [&](int r) {
        return r >= 0 && r < other.view.height ? other.ratio[static_cast<std::size_t>(r)] : 0.0;
      };
      const double a = ratio_at(below);
      const double b = ratio_at(below + 1);
      if (a > 0 && b > 0) depth = (1 - t) * a + t * b;
    }
    const RowEdges& model = grid.model[row];
    const RowEdges& seen = grid.image[row];
    const double stretch = (model.right - model.left) / (seen.right - seen.left);
    for (int x = 0; x < grid.view.width; ++x) {
      const double u = (x + 0.5) * grid.factor;
      const double source = (model.left + (u - seen.left) * stretch) / grid.factor - 0.5;
      grid.warped_tissue.at(x, y) = static_cast<float>(depth * along_row(grid.tissue, y, source));
      grid.warped_muscle.at(x, y) = static_cast<float>(depth * along_row(grid.muscle, y, source));
    }
  }
}

}  // namespace

SoftTissueImage::SoftTissueImage(image::FloatImage tissue_mm, image::FloatImage muscle_mm,
                                 int factor, std::vector<std::uint8_t> rows)
    : tissue_mm_(std::move(tissue_mm)),
      muscle_mm_(std::move(muscle_mm)),
      factor_(factor),
      rows_(std::move(rows)) {
  if (rows_.empty()) rows_.assign(static_cast<std::size_t>(tissue_mm_.height), 1);
}

bool SoftTissueImage::holds(double v) const {
  if (!usable_) return false;
  const double y = v / factor_ - 0.5;
  const int below = std::clamp(static_cast<int>(std::floor(y)), 0, tissue_mm_.height - 1);
  const int above = std::clamp(below + 1, 0, tissue_mm_.height - 1);
  return rows_[static_cast<std::size_t>(below)] != 0 && rows_[static_cast<std::size_t>(above)] != 0;
}

double SoftTissueImage::at(const Eigen::Vector2d& pixel) const {
  if (!usable_) return 0.0;
  const Eigen::Vector2d grid = pixel / static_cast<double>(factor_);
  return offset + tissue_per_mm * image::bilinear(tissue_mm_, grid) +
         muscle_per_mm * image::bilinear(muscle_mm_, grid);
}

double SoftTissueImage::share(double v, int blend_rows) const {
  if (!usable_) return 0.0;
  const int y = std::clamp(static_cast<int>(std::floor(v / factor_)), 0, tissue_mm_.height - 1);
  for (int d = 0; d <= blend_rows; ++d) {
    for (const int r : {y - d, y + d}) {
      if (r >= 0 && r < tissue_mm_.height && rows_[static_cast<std::size_t>(r)] != 0) {
        return 1.0 - static_cast<double>(d) / (blend_rows + 1);
      }
    }
  }
  return 0.0;
}

image::GrayImage16 without_soft_tissue(const image::GrayImage16& radiograph,
                                       const SoftTissueImage& model, int blend_rows) {
  image::GrayImage16 out = radiograph;
  if (!model.usable()) return out;
  for (int y = 0; y < out.height; ++y) {
    const double v = y + 0.5;
    const double share = model.share(v, blend_rows);
    if (share <= 0) continue;
    for (int x = 0; x < out.width; ++x) {
      const double tissue = model.at({x + 0.5, v}) - model.offset;
      const double value = radiograph.at(x, y) - share * tissue;
      out.at(x, y) = static_cast<std::uint16_t>(std::clamp(std::lround(value), 0L, 65535L));
    }
  }
  return out;
}

void SoftTissueImage::fit_law(const EdgeImage& image, const std::vector<std::uint8_t>& covered,
                              const SoftTissueModelOptions& options) {
  struct Pixel {
    double tissue = 0.0;
    double muscle = 0.0;
    double value = 0.0;
  };
  std::vector<Pixel> pixels;
  for (int y = 0; y < tissue_mm_.height; ++y) {
    if (rows_[static_cast<std::size_t>(y)] == 0) continue;
    for (int x = 0; x < tissue_mm_.width; ++x) {
      if (covered[tissue_mm_.index(x, y)] != 0) continue;
      const double tissue = tissue_mm_.at(x, y);
      const Eigen::Vector2d centre((x + 0.5) * factor_, (y + 0.5) * factor_);
      if (centre.x() >= image.width() || centre.y() >= image.height()) continue;
      pixels.push_back({tissue, muscle_mm_.at(x, y), image.sample(centre)});
    }
  }
  usable_ = false;
  std::vector<bool> kept(pixels.size(), true);
  Eigen::Vector3d law = Eigen::Vector3d::Zero();
  const auto residual = [&](const Pixel& pixel) {
    return std::abs(pixel.value - law[0] - law[1] * pixel.tissue - law[2] * pixel.muscle);
  };
  for (int round = 0; round < 3; ++round) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d right = Eigen::Vector3d::Zero();
    int count = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      if (!kept[i]) continue;
      const Eigen::Vector3d row(1.0, pixels[i].tissue, pixels[i].muscle);
      normal += row * row.transpose();
      right += row * pixels[i].value;
      ++count;
    }
    samples = count;
    if (count < std::max(options.min_samples, 3)) return;
    // Muscle-free views (no muscle in the model) leave M's column zero.
    if (normal(2, 2) <= 0) normal(2, 2) = 1.0;
    law = normal.ldlt().solve(right);
    std::vector<double> residuals;
    residuals.reserve(pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      if (kept[i]) residuals.push_back(residual(pixels[i]));
    }
    double sum = 0.0;
    for (const double r : residuals) sum += r * r;
    residual_rms = std::sqrt(sum / static_cast<double>(residuals.size()));
    if (round == 2) break;
    const double limit = 3.0 * 1.4826 * median_of(residuals);
    for (std::size_t i = 0; i < pixels.size(); ++i) kept[i] = residual(pixels[i]) <= limit;
  }
  offset = law[0];
  tissue_per_mm = law[1];
  muscle_per_mm = law[2];
  // The tissue must show: on radiographs of bones in air the limb's outline
  // catches a bone's edge and the law is noise.
  std::vector<double> depths;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (kept[i]) depths.push_back(pixels[i].tissue);
  }
  const double contrast = depths.empty() ? 0.0 : tissue_per_mm * median_of(depths);
  usable_ = std::isfinite(law.sum()) && tissue_per_mm > 0 && contrast > 5.0 * residual_rms;
}

std::vector<SoftTissueImage> model_soft_tissue(const std::vector<const mesh::IndexedMesh*>& bones,
                                               const std::vector<const mesh::IndexedMesh*>& muscles,
                                               const std::vector<image::RadiographView>& views,
                                               const std::vector<const EdgeImage*>& images,
                                               const SoftTissueModelOptions& options) {
  const auto positive = [](double value) { return std::isfinite(value) && value > 0; };
  if (!positive(options.pixel_mm) || !positive(options.fat_mm) ||
      !positive(options.edge_search_mm) ||
      !(std::isfinite(options.bone_margin_mm) && options.bone_margin_mm >= 0) ||
      !(std::isfinite(options.skin_margin_mm) && options.skin_margin_mm >= 0) ||
      options.threads < 1) {
    throw InvalidInputError(
        "soft-tissue model: pixel, fat, edge search, margin and depth must be finite (pixel, fat "
        "and search > 0) and threads >= 1");
  }
  if (bones.empty()) throw InvalidInputError("soft-tissue model: no bones");
  if (views.size() != images.size()) {
    throw InvalidInputError("soft-tissue model: " + std::to_string(views.size()) + " views but " +
                            std::to_string(images.size()) + " images");
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    image::validate_view(views[v]);
    if (images[v] == nullptr || images[v]->width() != views[v].width ||
        images[v]->height() != views[v].height) {
      throw InvalidInputError("soft-tissue model: the image of view '" + views[v].name +
                              "' is missing or not the view's size");
    }
  }
  std::vector<const mesh::IndexedMesh*> inside = bones;
  inside.insert(inside.end(), muscles.begin(), muscles.end());
  atlas::LimbEnvelopeOptions shape;
  shape.fat_mm = options.fat_mm;
  const mesh::AabbTree envelope(atlas::limb_envelope(inside, shape));
  std::vector<std::unique_ptr<mesh::AabbTree>> muscle_trees;
  std::vector<image::AttenuatingMesh> muscle_materials;
  for (const mesh::IndexedMesh* muscle : muscles) {
    muscle_trees.push_back(std::make_unique<mesh::AabbTree>(*muscle));
    muscle_materials.push_back({muscle_trees.back().get(), 1.0});
  }
  const std::vector<image::AttenuatingMesh> envelope_material = {{&envelope, 1.0}};

  // The model's path lengths on each view's grid, and its outline against the image's.
  std::vector<ViewGrid> grids;
  grids.reserve(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) {
    ViewGrid grid;
    grid.factor =
        std::max(1, static_cast<int>(std::lround(options.pixel_mm / views[v].pixel_spacing_mm)));
    grid.view = coarse_view(views[v], grid.factor);
    const image::DrrOptions drr{options.threads};
    grid.tissue = image::render_drr(grid.view, envelope_material, drr);
    grid.muscle = muscle_materials.empty()
                      ? image::FloatImage(grid.view.width, grid.view.height, 0.0F)
                      : image::render_drr(grid.view, muscle_materials, drr);
    if (options.fit_outline) {
      match_outline(grid, *images[v], options.edge_search_mm / views[v].pixel_spacing_mm);
    }
    grids.push_back(std::move(grid));
  }
  if (options.fit_outline && views.size() == 2) {
    // A slice's depth in one view is its width in the other: scale each
    // row's path lengths by the other view's width ratio at the same height.
    const std::vector<Eigen::Vector3d> axis = limb_axis(envelope.mesh());
    for (std::size_t v = 0; v < 2; ++v) {
      warp_to_outline(grids[v], grids[1 - v], axis);
    }
  }
  std::vector<SoftTissueImage> out;
  out.reserve(views.size());
  for (std::size_t v = 0; v < views.size(); ++v) {
    ViewGrid& grid = grids[v];
    const int width = grid.view.width;
    const int height = grid.view.height;
    const bool warped = !grid.warped_tissue.empty();
    const image::FloatImage& tissue = warped ? grid.warped_tissue : grid.tissue;
    // The law is fitted away from the bones and the skin's edge (where the
    // blur and the model's outline matter most).
    const int bone_radius =
        static_cast<int>(std::ceil(options.bone_margin_mm / grid.view.pixel_spacing_mm));
    std::vector<std::uint8_t> excluded =
        dilated(count_cover(bones, grid.view), width, height, bone_radius);
    std::vector<std::uint8_t> outside(excluded.size(), 0);
    for (std::size_t i = 0; i < outside.size(); ++i) outside[i] = tissue.pixels[i] <= 0 ? 1 : 0;
    const int skin_radius =
        static_cast<int>(std::ceil(options.skin_margin_mm / grid.view.pixel_spacing_mm));
    const std::vector<std::uint8_t> near_skin = dilated(outside, width, height, skin_radius);
    for (std::size_t i = 0; i < excluded.size(); ++i) excluded[i] |= near_skin[i];
    std::vector<std::uint8_t> rows;
    if (warped) {
      for (const double ratio : grid.ratio) rows.push_back(ratio > 0 ? 1 : 0);
    }
    SoftTissueImage model(std::move(warped ? grid.warped_tissue : grid.tissue),
                          std::move(warped ? grid.warped_muscle : grid.muscle), grid.factor,
                          std::move(rows));
    model.rows_matched = grid.rows_matched;
    model.median_width_ratio = grid.median_ratio;
    model.fit_law(*images[v], excluded, options);
    out.push_back(std::move(model));
  }
  return out;
}

}  // namespace mmm::outlines
