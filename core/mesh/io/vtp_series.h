#pragma once
// An animation folder for ParaView: one .vtp per part and frame plus the .pvd
// collection that indexes them by time, so that File > Open <stem>.pvd plays
// a gait trial (bone and muscle surfaces, action lines, fibres).
//
//   VtpSeriesWriter series(out_dir, "walk_01");
//   for (int i = 0; i < num_frames; ++i) {
//     series.add_surface(times[i], i, "femur_r", femur_at(i));
//     series.add_polylines(times[i], i, "fibres", fibres_at(i));
//   }
//   series.finish();  // out_dir/walk_01.pvd

#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh/io/pvd.h"
#include "core/mesh/io/vtp.h"
#include "core/mesh/io/vtp_polylines.h"
#include "core/mesh/mesh.h"

namespace mmm::mesh {

// Writes <folder>/<stem>/<part>_<frame>.vtp as frames are added (frame
// zero-padded to 4 digits: femur_r_0007.vtp) and <folder>/<stem>.pvd in
// finish(). Parts get their .pvd part number in first-seen order; finish()
// lists the entries sorted by time, then part. Folders are created as needed.
class VtpSeriesWriter {
 public:
  // `stem` names the .pvd and the subfolder of the frames; it must be a safe
  // file-name fragment like a part name (InvalidInputError otherwise).
  VtpSeriesWriter(std::filesystem::path folder, std::string stem);

  // Writes one frame of a surface (see write_vtp for the mesh and arrays).
  // `part` must be a non-empty file-name fragment of letters, digits, '_',
  // '-' and '.'; `time` finite; `frame` >= 0; a part takes each frame number
  // and each time once. Throws InvalidInputError for a bad argument or mesh
  // (nothing is written then), IoError when a folder or file cannot be
  // written, std::logic_error after finish().
  void add_surface(double time, int frame, const std::string& part, const IndexedMesh& mesh,
                   const VtpArrays& arrays = {});

  // Writes one frame of polylines (see write_vtp_polylines); same rules.
  void add_polylines(double time, int frame, const std::string& part, const Polylines& lines,
                     const VtpArrays& arrays = {});

  // Writes the .pvd. Throws InvalidInputError when nothing was added,
  // IoError when it cannot be written, std::logic_error when called twice.
  void finish();

  // <folder>/<stem>.pvd (written by finish()).
  [[nodiscard]] std::filesystem::path pvd_path() const;

  // Every file written so far, in order: the .vtp files, then the .pvd.
  [[nodiscard]] const std::vector<std::filesystem::path>& written_files() const { return written_; }

 private:
  // Checks the arguments of an add_* call and returns the .vtp path relative
  // to folder_, creating its subfolder.
  std::filesystem::path prepare(double time, int frame, const std::string& part);
  // Records a written frame for the .pvd.
  void record(double time, int frame, const std::string& part,
              const std::filesystem::path& relative);

  std::filesystem::path folder_;
  std::string stem_;
  std::vector<std::string> parts_;  // first-seen order: index = .pvd part number
  std::set<std::pair<std::string, int>> frames_taken_;
  std::set<std::pair<std::string, double>> times_taken_;
  std::vector<PvdEntry> entries_;
  std::vector<std::filesystem::path> written_;
  bool finished_ = false;
};

}  // namespace mmm::mesh
