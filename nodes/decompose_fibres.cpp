#include "nodes/decompose_fibres.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/atlas/atlas_io.h"
#include "core/directory_bundle.h"
#include "core/errors.h"
#include "core/fibres/fibre_mapping.h"
#include "core/fibres/fibre_quality.h"
#include "core/fibres/muscle_fibres.h"
#include "core/image/png.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/vtp_series.h"
#include "core/parallel_for.h"
#include "core/wrapping/muscle_frames.h"
#include "core/wrapping/muscle_hulls.h"
#include "core/wrapping/muscle_wrapping.h"
#include "nodes/fibre_picture.h"
#include "nodes/muscle_selection.h"
#include "nodes/name_list.h"
#include "nodes/number_text.h"

namespace mmm::nodes {
namespace {

using fibres::DecompositionMethod;

// "muscle=method,..." -> map; names checked against the atlas.
std::map<std::string, DecompositionMethod> method_overrides(const std::string& text,
                                                            const atlas::Atlas& atlas) {
  std::map<std::string, DecompositionMethod> overrides;
  for (const std::string& item : split_names(text)) {
    const auto equals = item.find('=');
    const std::string muscle = item.substr(0, equals);
    const auto method = equals == std::string::npos
                            ? std::nullopt
                            : fibres::method_from_name(item.substr(equals + 1));
    if (!method || atlas.find_muscle(muscle) == nullptr) {
      throw InvalidInputError("decompose_fibres: parameter 'methods': '" + item +
                              "' is not MUSCLE=METHOD with an atlas muscle and one of slicing, "
                              "harmonic, mass_spring, cadaver");
    }
    overrides[muscle] = *method;
  }
  return overrides;
}

mesh::Polylines as_polylines(const std::vector<fibres::Fibre>& fibres) {
  mesh::Polylines lines;
  Eigen::Index points = 0;
  for (const fibres::Fibre& f : fibres) points += f.rows();
  lines.points.resize(points, 3);
  Eigen::Index row = 0;
  for (const fibres::Fibre& f : fibres) {
    std::vector<int> line;
    for (Eigen::Index k = 0; k < f.rows(); ++k) {
      line.push_back(static_cast<int>(row));
      lines.points.row(row++) = f.row(k);
    }
    lines.lines.push_back(std::move(line));
  }
  return lines;
}

// One muscle's decomposition at rest and in every frame, computed on a
// worker thread and written out in muscle order.
struct MuscleResult {
  DecompositionMethod method = DecompositionMethod::kSlicing;
  fibres::MuscleFibres rest;
  fibres::FibreQuality quality;
  mesh::IndexedMesh rest_surface;                  // kept for the pictured muscle only
  std::vector<std::vector<fibres::Fibre>> frames;  // per animation frame
  double field_seconds = 0.0;
  double frame_seconds = 0.0;
  double frames_inside = 1.0;  // the worst frame's inside fraction, against that frame's surface
};

}  // namespace

workflow::NodeSpec DecomposeFibres::spec() {
  using workflow::port::Atlas;
  using workflow::port::File;
  using workflow::port::MuscleFrames;
  using workflow::port::Report;
  const fibres::DecompositionOptions d;
  const wrapping::MuscleWrappingOptions w;
  return workflow::NodeSpec{
      "decompose_fibres", 2,
      "Every muscle's volume filled with fibres (slicing, harmonic, mass-spring or cadaver "
      "method), at rest and in every frame of a wrapped motion"}
      .resources(2, 4096)
      .input<Atlas>("atlas", "The (scaled) atlas")
      .optional_input<MuscleFrames>(
          "wrapped",
          "A wrapping node's wrapped motion of this atlas (wrap_muscles or simulate_muscles): "
          "each muscle is decomposed on its rest surface there, then in every stored frame")
      .param_enum("method", "slicing", {"slicing", "harmonic", "mass_spring", "cadaver"},
                  "Decomposition method of every muscle (cadaver: this atlas has no measured "
                  "fibres, so four stand-ins traced on the muscle are used)")
      .param<std::string>("methods", "",
                          "Per-muscle methods overriding 'method': MUSCLE=METHOD,...")
      .param<std::int64_t>("fibres", d.fibres,
                           "Fibres per muscle (mass-spring and cadaver: the "
                           "nearest square)",
                           {.min = 9, .max = 10000})
      .param<std::int64_t>("segments", d.segments, "Segments per fibre", {.min = 2, .max = 1000})
      .param<std::int64_t>("target_faces", w.target_faces,
                           "Muscle surface resolution, as wrap_muscles's target_faces (0: full); "
                           "with a wrapped motion, its rest surfaces are used instead",
                           {.min = 0, .max = 1000000})
      .param<std::string>("muscles", "",
                          "Comma-separated muscle names; empty: every muscle of the atlas")
      .param<std::string>("picture_muscle", "gluteus_medius_r",
                          "The muscle shown in the picture (the first one when absent)")
      .param<std::int64_t>("threads", 0,
                           "Worker threads (muscles in parallel; the outputs do not depend on "
                           "it); 0: the machine's",
                           {.min = 0, .max = 256})
      .output<File>("fibres", "Folder bundle: fibres.pvd + .vtp polylines per muscle and frame")
      .output<File>("lengths", "CSV: muscle, method, fibre, frame, time (s), length (mm)")
      .output<File>("picture", "PNG: a muscle with its fibres, front and side")
      .output<Report>("report",
                      "Per muscle: method, quality at rest, worst inside fraction over the frames, "
                      "tendon gaps, times");
}

void DecomposeFibres::run(workflow::NodeContext& context) {
  const auto started = std::chrono::steady_clock::now();
  const std::filesystem::path atlas_dir = context.scratch_dir() / "atlas";
  unpack_directory(context.input_bytes("atlas"), atlas_dir, "input 'atlas'");
  const atlas::Atlas atlas = atlas::read_atlas(atlas_dir);
  const std::vector<const atlas::Muscle*> muscles =
      selected_muscles(atlas, context.text("muscles"), "decompose_fibres");
  const DecompositionMethod default_method = *fibres::method_from_name(context.text("method"));
  const auto overrides = method_overrides(context.text("methods"), atlas);
  fibres::DecompositionOptions options;
  options.fibres = static_cast<int>(context.integer("fibres"));
  options.segments = static_cast<int>(context.integer("segments"));
  std::map<std::string, mesh::IndexedMesh> bones;
  std::mutex bones_mutex;
  const auto bone_surface = [&](const std::string& name) -> const mesh::IndexedMesh& {
    const std::scoped_lock lock(bones_mutex);
    auto found = bones.find(name);
    if (found == bones.end()) {
      const atlas::Bone* bone = atlas.find_bone(name);
      found = bones.emplace(name, atlas::load_mesh(atlas_dir, bone->meshes)).first;
    }
    return found->second;
  };
  wrapping::MuscleFrames wrapped;
  if (context.has_input("wrapped")) {
    wrapped = wrapping::decode_muscle_frames(context.input_bytes("wrapped"),
                                             "decompose_fibres: input 'wrapped'");
    for (const atlas::Muscle* muscle : muscles) {
      if (wrapped.find_muscle(muscle->name) == nullptr) {
        throw InvalidInputError("decompose_fibres: input 'wrapped' has no muscle '" + muscle->name +
                                "'; hint: wrap the same muscles, or choose them with 'muscles'");
      }
    }
  }
  const std::vector<double>& times = wrapped.times;

  const std::filesystem::path folder = context.scratch_dir() / "fibres";
  std::filesystem::remove_all(folder);
  mesh::VtpSeriesWriter series(folder, "fibres");
  std::string csv = "muscle,method,fibre,frame,time_s,length_mm\n";
  nlohmann::json rows = nlohmann::json::array();
  double worst_inside = 1.0;
  const std::string picture_name = context.text("picture_muscle");
  const atlas::Muscle* pictured = atlas.find_muscle(picture_name);
  if (pictured == nullptr) pictured = muscles.front();
  // Each muscle on a worker thread; the outputs are written in muscle order
  // afterwards, so they do not depend on the number of threads.
  std::vector<MuscleResult> results(muscles.size());
  std::mutex progress_mutex;
  std::size_t done = 0;
  const int threads = context.integer("threads") > 0 ? static_cast<int>(context.integer("threads"))
                                                     : machine_threads();
  parallel_for(muscles.size(), threads, [&](std::size_t m) {
    const atlas::Muscle& muscle = *muscles[m];
    MuscleResult& out = results[m];
    const auto found = overrides.find(muscle.name);
    out.method = found != overrides.end() ? found->second : default_method;
    fibres::DecompositionOptions muscle_options = options;
    muscle_options.architecture = muscle.architecture;
    const wrapping::FramedMuscle* framed = wrapped.find_muscle(muscle.name);
    const fibres::MuscleFibreModel model(
        muscle.name,
        framed != nullptr
            ? framed->rest
            : wrapping::wrapping_surface(muscle, atlas_dir, context.integer("target_faces")),
        fibres::attachment_samples(muscle, bone_surface), out.method, muscle_options);
    out.rest = model.decompose_at_rest();
    out.quality = fibres::measure_fibre_quality(
        model.rest(), out.rest.fibres, out.rest.attachments.origin, out.rest.attachments.insertion);
    if (&muscle == pictured) out.rest_surface = model.rest();
    for (std::size_t k = 0; k < times.size(); ++k) {
      mesh::IndexedMesh surface = model.rest();
      surface.V = framed->positions[k].cast<double>();
      fibres::MuscleFibres result = model.decompose(
          surface.V, [&](const std::string& bone) { return wrapped.pose(bone, k); });
      out.frame_seconds += result.seconds;
      out.frames_inside =
          std::min(out.frames_inside, fibres::inside_fraction(surface, result.fibres));
      out.frames.push_back(std::move(result.fibres));
    }
    out.field_seconds = model.field_seconds();
    const std::scoped_lock lock(progress_mutex);
    context.progress(static_cast<std::int64_t>(++done), static_cast<std::int64_t>(muscles.size()),
                     "fibres of " + muscle.name);
  });

  std::vector<fibres::Fibre> pictured_fibres;
  mesh::IndexedMesh pictured_surface;
  for (std::size_t m = 0; m < muscles.size(); ++m) {
    const atlas::Muscle& muscle = *muscles[m];
    MuscleResult& result = results[m];
    worst_inside = std::min(worst_inside, result.quality.inside_fraction);
    if (&muscle == pictured) {
      pictured_fibres = result.rest.fibres;
      pictured_surface = std::move(result.rest_surface);
    }
    const auto add_frame = [&](const std::vector<fibres::Fibre>& fibres, int frame, double time) {
      series.add_polylines(time, frame, muscle.name, as_polylines(fibres));
      for (std::size_t f = 0; f < fibres.size(); ++f) {
        csv += muscle.name + "," + std::string(fibres::method_name(result.method)) + "," +
               std::to_string(f) + "," + std::to_string(frame) + "," + fixed(time, 4) + "," +
               fixed(fibres::fibre_length(fibres[f]), 3) + "\n";
      }
    };
    if (times.empty()) {
      add_frame(result.rest.fibres, 0, 0.0);
    } else {
      for (std::size_t k = 0; k < times.size(); ++k) {
        add_frame(result.frames[k], static_cast<int>(k), times[k]);
      }
    }
    result.frames.clear();
    nlohmann::json row = result.quality;
    row["muscle"] = muscle.name;
    row["method"] = std::string(fibres::method_name(result.method));
    row["stand_in_measured"] = result.rest.stand_in_measured;
    row["moved_inside"] = result.rest.moved_inside;
    row["rest_ms"] = 1000.0 * result.rest.seconds;
    row["field_ms"] = 1000.0 * result.field_seconds;
    row["frames"] = times.size();
    row["frames_ms"] = 1000.0 * result.frame_seconds;
    row["frames_min_inside_fraction"] = result.frames_inside;
    worst_inside = std::min(worst_inside, result.frames_inside);
    // The tendons the segmentation left out: from the muscle's end patches
    // (where the fibres end) to the bone areas, at rest.
    row["origin_tendon_gap_mm"] = result.rest.origin_gap_mm;
    row["insertion_tendon_gap_mm"] = result.rest.insertion_gap_mm;
    rows.push_back(row);
  }
  if (worst_inside < 0.99) {
    context.warn("a muscle keeps only " + fixed(100.0 * worst_inside, 2) +
                 " % of its fibre points inside (see the report)");
  }
  series.finish();
  context.set_output("fibres", pack_directory(folder));
  context.set_output("lengths", csv);
  const std::filesystem::path picture = context.scratch_dir() / "fibres.png";
  image::write_png(fibre_picture(pictured_surface, pictured_fibres), picture);
  context.set_output_file("picture", picture);
  context.set_output(
      "report",
      nlohmann::json{
          {"muscles", rows},
          {"frames", times.size()},
          {"wrapping_pathway", wrapped.pathway},
          {"fibres", options.fibres},
          {"segments", options.segments},
          {"min_inside_fraction", worst_inside},
          {"picture_muscle", pictured->name},
          {"node_seconds",
           std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()}}
          .dump(2));
  context.progress(static_cast<std::int64_t>(muscles.size()),
                   static_cast<std::int64_t>(muscles.size()), "done");
}

}  // namespace mmm::nodes
