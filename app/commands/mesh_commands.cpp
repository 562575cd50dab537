// mmm mesh info|convert|decimate|survey: the command-line face of core/mesh.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "app/commands/mesh_summary.h"
#include "core/errors.h"
#include "core/mesh/decimate.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/io/vtp.h"

namespace mmm::app {
namespace {

// Coordinates are millimetres once multiplied by --scale (1000 for files in
// metres such as OpenSim's geometry); every printed unit is mm.
constexpr const char* kUnits = "mm";

void apply_scale(mesh::IndexedMesh& mesh, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw InvalidInputError("--scale must be a positive finite number, got " +
                            std::to_string(scale));
  }
  if (scale != 1.0) mesh.V *= scale;
}

struct InfoArgs {
  std::string file;
  bool json = false;
  double scale = 1.0;
};

void run_info(const InfoArgs& args) {
  mesh::IndexedMesh mesh = mesh::read_mesh(args.file);
  apply_scale(mesh, args.scale);
  const MeshSummary summary = summarize_mesh(mesh, args.file);
  if (args.json) {
    std::cout << to_json(summary, kUnits).dump(2) << '\n';
  } else {
    std::cout << to_text(summary, kUnits);
  }
}

struct ConvertArgs {
  std::string input;
  std::string output;
  double scale = 1.0;
  bool ascii = false;
};

void run_convert(const ConvertArgs& args) {
  mesh::IndexedMesh mesh = mesh::read_mesh(args.input);
  apply_scale(mesh, args.scale);
  mesh::write_mesh(mesh, args.output, {.ascii = args.ascii});
  std::cout << "wrote " << args.output << " (" << mesh.num_vertices() << " vertices, "
            << mesh.num_faces() << " faces)\n";
}

struct DecimateArgs {
  std::string input;
  std::string output;
  Eigen::Index faces = 0;
  double max_normal_deviation = 60.0;
};

void run_decimate(const DecimateArgs& args) {
  const mesh::IndexedMesh mesh = mesh::read_mesh(args.input);
  mesh::DecimateReport report;
  const mesh::IndexedMesh coarse = mesh::decimate(
      mesh, {.target_faces = args.faces, .max_normal_deviation_degrees = args.max_normal_deviation},
      &report);
  mesh::write_mesh(coarse, args.output);
  std::cout << "wrote " << args.output << ": " << report.faces_before << " -> "
            << report.faces_after << " faces\n";
}

struct SurveyArgs {
  std::string folder;
  std::string out;
  double scale = 1.0;
  Eigen::Index lod_faces = 0;
  bool json = false;
};

std::vector<std::filesystem::path> mesh_files_under(const std::filesystem::path& folder) {
  if (!std::filesystem::is_directory(folder)) {
    throw IoError(folder, "not a folder (mmm mesh survey takes a folder of meshes)");
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    try {
      mesh::format_from_extension(entry.path());
      files.push_back(entry.path());
    } catch (const IoError&) {
      // Not a mesh file (README, XML, ...): not part of the survey.
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void run_survey(const SurveyArgs& args) {
  const std::filesystem::path folder = args.folder;
  const std::filesystem::path out = args.out;
  const auto files = mesh_files_under(folder);
  if (!out.empty()) std::filesystem::create_directories(out / "vtp");

  nlohmann::json report = nlohmann::json::array();
  std::ostringstream csv;
  csv << "file,vertices,faces,closed,watertight,volume,area,components,problems\n";
  std::printf("%-58s %7s %7s %-6s %14s %12s\n", "file", "verts", "faces", "closed", "volume",
              "area");
  int failures = 0;
  for (const auto& file : files) {
    const std::string name = std::filesystem::relative(file, folder).string();
    try {
      mesh::IndexedMesh mesh = mesh::read_mesh(file);
      apply_scale(mesh, args.scale);
      const MeshSummary summary = summarize_mesh(mesh, name);
      report.push_back(to_json(summary, kUnits));
      const auto& c = summary.check;
      std::string volume = "n/a";
      if (summary.has_volume()) {
        std::array<char, 32> text{};
        std::snprintf(text.data(), text.size(), "%.1f", summary.properties.volume);
        volume = text.data();
      }
      std::string problems;
      for (const auto& p : c.problems()) problems += (problems.empty() ? "" : "; ") + p;
      std::printf("%-58s %7ld %7ld %-6s %14s %12.1f\n", name.c_str(), static_cast<long>(c.vertices),
                  static_cast<long>(c.faces), c.closed() ? "yes" : "no", volume.c_str(),
                  summary.properties.area);
      csv << csv_field(name) << ',' << c.vertices << ',' << c.faces << ',' << c.closed() << ','
          << c.watertight() << ',' << volume << ',' << summary.properties.area << ','
          << c.connected_components << ',' << csv_field(problems) << '\n';
      if (!out.empty()) {
        std::filesystem::path stem = out / "vtp" / name;
        stem.replace_extension();
        std::filesystem::create_directories(stem.parent_path());
        mesh::write_vtp(mesh, stem.string() + ".vtp");
        if (args.lod_faces > 0 && mesh.num_faces() > args.lod_faces && c.manifold()) {
          const auto coarse = mesh::decimate(mesh, {.target_faces = args.lod_faces});
          mesh::write_vtp(coarse, stem.string() + "_lod" + std::to_string(args.lod_faces) + ".vtp");
        }
      }
    } catch (const std::exception& e) {
      ++failures;
      std::printf("%-58s FAILED: %s\n", name.c_str(), e.what());
      report.push_back({{"file", name}, {"error", e.what()}});
      csv << csv_field(name) << ",,,,,,,," << csv_field(std::string("FAILED: ") + e.what()) << '\n';
    }
  }
  std::printf("%zu meshes, %d unreadable; volume in %s^3, area in %s^2\n", files.size(), failures,
              kUnits, kUnits);
  if (!out.empty()) {
    std::ofstream(out / "survey.json") << report.dump(2) << '\n';
    std::ofstream(out / "survey.csv") << csv.str();
    std::printf("wrote %s/survey.{csv,json} and %s/vtp/*.vtp (open them in ParaView)\n",
                out.string().c_str(), out.string().c_str());
  }
  if (args.json) std::cout << report.dump(2) << '\n';
  if (failures > 0) set_exit_code(1);
}

}  // namespace

void register_mesh_commands(CLI::App& app) {
  auto* mesh = app.add_subcommand("mesh", "Inspect, convert and simplify surface meshes");
  mesh->require_subcommand(1);

  auto info_args = std::make_shared<InfoArgs>();
  auto* info = mesh->add_subcommand(
      "info", "Health report (closedness, manifoldness, orientation) and measures of one mesh");
  info->add_option("FILE", info_args->file, "Mesh file (.stl .obj .ply .off .vtp)")->required();
  info->add_flag("--json", info_args->json, "Print JSON instead of text");
  info->add_option("--scale", info_args->scale,
                   "Multiply coordinates to get mm (1000 for files in metres)");
  info->callback([info_args] { run_info(*info_args); });

  auto convert_args = std::make_shared<ConvertArgs>();
  auto* convert = mesh->add_subcommand("convert", "Convert between mesh formats (by extension)");
  convert->add_option("INPUT", convert_args->input, "Input mesh")->required();
  convert->add_option("OUTPUT", convert_args->output, "Output mesh")->required();
  convert->add_option("--scale", convert_args->scale, "Multiply coordinates (1000: m -> mm)");
  convert->add_flag("--ascii", convert_args->ascii, "ASCII STL/PLY instead of binary");
  convert->callback([convert_args] { run_convert(*convert_args); });

  auto decimate_args = std::make_shared<DecimateArgs>();
  auto* decimate = mesh->add_subcommand(
      "decimate", "Lower-resolution copy by quadric edge collapses (OpenMesh Decimater)");
  decimate->add_option("INPUT", decimate_args->input, "Input mesh")->required();
  decimate->add_option("OUTPUT", decimate_args->output, "Output mesh")->required();
  decimate->add_option("--faces", decimate_args->faces, "Target face count")
      ->required()
      ->check(CLI::Range(Eigen::Index{4}, Eigen::Index{1} << 40));
  decimate
      ->add_option("--max-normal-deviation", decimate_args->max_normal_deviation,
                   "Largest normal change per collapse (degrees)")
      ->check(CLI::Range(1.0, 180.0));
  decimate->callback([decimate_args] { run_decimate(*decimate_args); });

  auto survey_args = std::make_shared<SurveyArgs>();
  auto* survey = mesh->add_subcommand(
      "survey", "Check and measure every mesh under a folder; table, CSV/JSON and VTP copies");
  survey->add_option("FOLDER", survey_args->folder, "Folder searched recursively")->required();
  survey->add_option("--out", survey_args->out,
                     "Write survey.csv, survey.json and vtp/ (ParaView) here");
  survey->add_option("--scale", survey_args->scale, "Multiply coordinates (1000: m -> mm)");
  survey->add_option("--lod-faces", survey_args->lod_faces,
                     "Also write a decimated copy with this many faces");
  survey->add_flag("--json", survey_args->json, "Print the JSON report");
  survey->callback([survey_args] { run_survey(*survey_args); });
}

}  // namespace mmm::app
