// The paper's beam comparison (section 4.3) end to end on a small beam: FEM and VDM driven
// through the same nodes, VDM's moduli fitted, the CSV written with the contract's columns.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/cli/commands.hpp"
#include "app/run/output_dir.hpp"
#include "app/studies/paper_beam.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

BeamConfig small_beam() {
  BeamConfig c;
  c.cells_across = 2;
  c.cells_along = 8;
  c.steps = 5;
  return c;
}

TEST(PaperBeam, RunsEndToEndAndWritesTheCsv) {
  const std::string out = (vdmsim::test::scratch_dir("paper_beam") / "out").string();
  std::filesystem::remove_all(out);
  std::ostringstream o, e;
  std::string error;
  ASSERT_TRUE(prepare_output_dir(out, error)) << error;
  ASSERT_EQ(paper_beams({BeamCase::stretch, BeamCase::bend, BeamCase::twist}, small_beam(), out, o, e), 0) << e.str();
  for (const char* name : {"stretch", "bend", "twist"}) {
    std::ifstream f(std::filesystem::path(out) / ("beam-" + std::string(name) + ".csv"));
    ASSERT_TRUE(f) << name;
    std::string header;
    std::getline(f, header);
    EXPECT_EQ(header, "step,point,vdm_disp,fem_disp,vdm_volume_rel_error,fem_volume_rel_error");
    int rows = 0;
    for (std::string line; std::getline(f, line);) ++rows;
    EXPECT_EQ(rows, 3 * (small_beam().steps + 1)) << name;
  }
  EXPECT_NE(o.str().find("beam-twist"), std::string::npos) << o.str();
}

TEST(PaperBeam, VdmKeepsVolumeFemFollowsItsOwnPhysicsAndStretchMatches) {
  const BeamStudy st = run_beam_study(small_beam(), {BeamCase::stretch, BeamCase::bend, BeamCase::twist});
  ASSERT_EQ(st.cases.size(), 3u);
  for (const BeamCaseResult& r : st.cases) {
    EXPECT_TRUE(r.fem.converged) << to_string(r.which);
    for (double v : r.vdm.volume_rel) EXPECT_LT(std::abs(v), 1e-9) << to_string(r.which);
    // The end really moved, in both models.
    EXPECT_GT(r.fem.u.back().row(2).norm(), 1e-3) << to_string(r.which);
    EXPECT_GT(r.vdm.u.back().row(2).norm(), 0.0) << to_string(r.which);
  }
  // Stretching 30 %: the corotational FEM loses volume (nu = 0.45 < 0.5 and a linear
  // volumetric strain), about (1 + e)(1 - nu e)^2 - 1 in the uniform part.
  EXPECT_LT(st.cases[0].fem.volume_rel.back(), -0.005);
  // After fitting, the stretch matches to a few per cent; bend and twist are what VDM's
  // capsule Laplacian cannot do (README): their difference is measured, not bounded here.
  EXPECT_LT(st.cases[0].mean_relative_difference, 0.1);
  EXPECT_GT(st.used.bulk, 0.0);
  EXPECT_GT(st.used.connectivity, 0.0);
}

}  // namespace
}  // namespace vdmsim
