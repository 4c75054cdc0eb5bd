// `vdmsim accuracy --ladder --quick` end to end: the model ladder's table and plot, and what
// the physics says they must show against the reference FEM (issue 42's targets for the
// elastic core; the paper's VDM losing the bend and the twist). Times are written, not asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using LadderCsvRow = std::map<std::string, std::string>;

std::vector<std::string> ladder_csv_cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

// The rung of `test_case` and `model` (for vdm_core, the cell in `resolution`: "cell 5 mm").
const LadderCsvRow* ladder_rung(const std::vector<LadderCsvRow>& rows, const std::string& test_case,
                                const std::string& model, const std::string& reference, const std::string& cell = "") {
  for (const LadderCsvRow& r : rows)
    if (r.at("case") == test_case && r.at("model") == model && r.at("reference") == reference &&
        (cell.empty() || r.at("resolution").find("cell " + cell + " mm") != std::string::npos))
      return &r;
  return nullptr;
}

double ladder_number(const LadderCsvRow* r, const char* column) {
  return r && !r->at(column).empty() ? std::stod(r->at(column)) : -1;
}

}  // namespace

TEST(AccuracyLadderCli, QuickLadderMeetsTheTargetsAgainstTheFem) {
  const fs::path out = fs::path(VDMSIM_BUILD_DIR) / "test-output" / "accuracy_ladder";
  fs::remove_all(out);
  const std::string cmd = std::string(VDMSIM_BINARY) + " accuracy --ladder --quick --jobs 2 --out " + out.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);

  std::ifstream csv(out / "ladder.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  ASSERT_EQ(line,
            "scenario,case,model,reference,resolution,nodes,median_ms,measured_median_ms,yardstick_ms,"
            "time_vs_reference,error,force_error,volume_rel_error,detail,folder,note");
  const std::vector<std::string> header = ladder_csv_cells(line);
  std::vector<LadderCsvRow> rows;
  while (std::getline(csv, line)) {
    const std::vector<std::string> cells = ladder_csv_cells(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    LadderCsvRow r;
    for (size_t k = 0; k < cells.size(); ++k) r[header[k]] = cells[k];
    rows.push_back(r);
  }
  // Every rung ran: the surface models keep the volume to round-off.
  for (const LadderCsvRow& r : rows) {
    ASSERT_FALSE(r.at("median_ms").empty()) << r.at("folder") << " failed: " << r.at("note");
    if (r.at("model") != "fem") {
      EXPECT_LT(std::abs(std::stod(r.at("volume_rel_error"))), 1e-9) << r.at("folder");
    }
  }

  // The references are converged enough to measure against: the FEM one mesh coarser is within
  // 10 % on the punch (dent and force) and 5 % on the beams.
  EXPECT_LT(ladder_number(ladder_rung(rows, "punch", "fem", "0"), "error"), 0.10);
  EXPECT_LT(ladder_number(ladder_rung(rows, "punch", "fem", "0"), "force_error"), 0.10);
  for (const char* beam : {"stretch", "bend", "twist"}) {
    const double e = ladder_number(ladder_rung(rows, beam, "fem", "0"), "error");
    EXPECT_GE(e, 0) << beam;
    EXPECT_LT(e, 0.05) << beam;
  }

  // The elastic core at 5 mm cells meets the targets against the FEM: the punch's force
  // 30 % and dent 35 %, the beams' stretch, bend and twist 10, 15 and 30 %.
  const LadderCsvRow* punch = ladder_rung(rows, "punch", "vdm_core", "0", "5");
  ASSERT_TRUE(punch);
  EXPECT_LT(ladder_number(punch, "force_error"), 0.30);
  EXPECT_LT(ladder_number(punch, "error"), 0.35);
  const std::map<std::string, double> targets = {{"stretch", 0.10}, {"bend", 0.15}, {"twist", 0.30}};
  for (const auto& [beam, target] : targets) {
    const LadderCsvRow* core = ladder_rung(rows, beam, "vdm_core", "0", "5");
    const LadderCsvRow* coarse = ladder_rung(rows, beam, "vdm_core", "0", "10");
    ASSERT_TRUE(core && coarse) << beam;
    EXPECT_GE(ladder_number(core, "error"), 0) << beam;
    EXPECT_LT(ladder_number(core, "error"), target) << beam;
    if (beam != "stretch") {
      // Where the core carries a rotation along the beam, finer cells carry it closer.
      EXPECT_LT(ladder_number(core, "error"), ladder_number(coarse, "error")) << beam;
      // The paper's VDM loses the bend and the twist (its bulk term anchors every node to its
      // rest position): far beyond the target, and beyond the core's error.
      const double paper = ladder_number(ladder_rung(rows, beam, "vdm_paper", "0"), "error");
      EXPECT_GT(paper, target) << beam;
      EXPECT_GT(paper, 3 * ladder_number(core, "error")) << beam;
    }
  }
  // The liver probe ran every model against its FEM (its errors are the models' differences
  // there: the quick ladder's FEM is the 642-node liver's, not converged).
  for (const char* model : {"vdm_paper", "vdm_membrane", "vdm_core"})
    EXPECT_GT(ladder_number(ladder_rung(rows, "liver_probe", model, "0"), "error"), 0) << model;

  // The plot: a PNG, one panel per case and measure.
  std::ifstream png(out / "ladder.png", std::ios::binary);
  char magic[8] = {};
  png.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_GT(fs::file_size(out / "ladder.png"), 20000u);
}
