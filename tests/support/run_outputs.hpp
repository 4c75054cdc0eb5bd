#pragma once
// Reading a run's output folder back in tests that compare two runs (a resumed one and one that
// was never stopped): a file's bytes, and metrics.csv without its wall-clock column.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace vdmsim::test {

// The file's bytes (empty when it cannot be read).
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// metrics.csv without the step_ms column (wall-clock time, different in every run).
inline std::vector<std::string> metrics_without_timing(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) cells.push_back(c);
    if (line.back() == ',') cells.push_back("");
    if (cells.size() > 2) cells.erase(cells.begin() + 2);
    std::string joined;
    for (const auto& x : cells) joined += x + ",";
    rows.push_back(joined);
  }
  return rows;
}

}  // namespace vdmsim::test
