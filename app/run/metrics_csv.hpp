#pragma once
// DIR/metrics.csv: one row per frame, each on disk before the frame counts as done. A
// resumed run keeps the rows of the frames before it; a failed write is cut back to the last
// whole row, so that the file stays valid.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "app/simulation/scene_simulation.hpp"

namespace vdmsim {

class MetricsCsv {
 public:
  // Writes the header (and, when `resume`, the first `start` rows of the file there).
  // `stress`: the model computes stress (its column filled). `organs`: with several organs,
  // their names: each gets columns of its own after the scene's. Returns -1 when the file is
  // ready, otherwise the exit code after a message on `err`.
  int open(const std::filesystem::path& dir, int start, bool resume, bool stress, std::ostream& err,
           const std::vector<std::string>& organs = {});
  // Frame f's row. False when it could not be written, with `reason`; the file is then cut
  // back to its last whole row and closed.
  bool write(int f, const SceneSimulation& sim, std::string& reason);
  void flush();
  // Keeps the first `rows` rows written by this run (and the kept ones before them): the
  // frames whose images all reached the disk after an image write failure.
  void cut_back(int rows);

 private:
  std::filesystem::path path_;
  std::ofstream file_;
  bool stress_ = false;
  size_t organ_columns_ = 0;  // organs with columns of their own
  std::uintmax_t good_size_ = 0;      // the file's size after its last whole row
  std::uintmax_t rows_base_ = 0;      // its size before this run's first row
  std::vector<std::uintmax_t> row_end_;  // its size after each row of this run
};

}  // namespace vdmsim
