// The paper's cube experiments (sections 4.1 and 4.2): volume kept, anisotropy reproduced.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/cli/commands.hpp"
#include "app/studies/paper_cube.hpp"

namespace vdmsim {
namespace {

TEST(PaperCube, ThirtyPercentCompressionKeepsVolumeEveryStepWithEverySolver) {
  for (vdm::SolverMethod method : {vdm::SolverMethod::reference, vdm::SolverMethod::structured,
                                   vdm::SolverMethod::direct}) {
    CubeCompression cfg;
    cfg.compression = 0.3;
    cfg.solver.method = method;
    const CubeResult r = run_cube_stress(cfg);
    ASSERT_EQ(r.volume_rel_error.size(), size_t(cfg.steps) + 1);
    for (size_t k = 0; k < r.volume_rel_error.size(); ++k)
      EXPECT_LT(std::abs(r.volume_rel_error[k]), 1e-6) << vdm::to_string(method) << " step " << k;
    // The plate did compress it by 30 %, and the fluid pressure rose.
    EXPECT_NEAR(r.points[0].displacement.back().z() / cfg.side, -0.3 * 0.75, 0.1);
    EXPECT_GT(r.pressure.back(), 0.0);
  }
}

TEST(PaperCube, StressGrowsWithCompressionAndBulgeFacesOutward) {
  const CubeResult r = run_cube_stress(CubeCompression{});
  // B, on the face y = -L/2, bulges outward (-y) more and more.
  const auto& B = r.points[1];
  for (size_t k = 1; k < B.displacement.size(); ++k) EXPECT_LT(B.displacement[k].y(), B.displacement[k - 1].y());
  // The stress at each point is zero at rest and non-zero once compressed.
  for (const auto& p : r.points) {
    EXPECT_EQ(p.stress.front().norm(), 0.0);
    EXPECT_GT(p.stress.back().norm(), 0.0);
  }
}

TEST(PaperAnisotropy, ReproducesFigure6) {
  CubeCompression cfg;
  const CubeResult uni = run_anisotropy(cfg, AnisotropyCase::uniform);
  const CubeResult xinf = run_anisotropy(cfg, AnisotropyCase::x_infinite);
  const CubeResult prefy = run_anisotropy(cfg, AnisotropyCase::prefer_y);
  for (size_t k = 1; k < uni.volume_rel_error.size(); ++k) {
    // (a) uniform: B (moving along y) and C (along x) move alike.
    const double b = std::abs(uni.points[1].displacement[k].y());
    const double c = std::abs(uni.points[2].displacement[k].x());
    EXPECT_NEAR(b, c, 0.02 * b) << "step " << k;
    // (b) x infinite: C, constrained along x, barely moves; B moves more than in (a).
    const double bx = std::abs(xinf.points[1].displacement[k].y());
    const double cx = std::abs(xinf.points[2].displacement[k].x());
    EXPECT_LT(cx, 1e-9 * bx) << "step " << k;
    EXPECT_GT(bx, b) << "step " << k;
    // (c) prefer y: B moves more than in (a), C less.
    EXPECT_GT(std::abs(prefy.points[1].displacement[k].y()), b) << "step " << k;
    EXPECT_LT(std::abs(prefy.points[2].displacement[k].x()), c) << "step " << k;
    // A, under the plate, follows the plate in all three cases.
    EXPECT_EQ(uni.points[0].displacement[k].z(), xinf.points[0].displacement[k].z());
    EXPECT_EQ(uni.points[0].displacement[k].z(), prefy.points[0].displacement[k].z());
    for (const CubeResult* r : {&uni, &xinf, &prefy}) EXPECT_LT(std::abs(r->volume_rel_error[k]), 1e-6);
  }
}

std::vector<std::string> lines_of(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(f, l);) out.push_back(l);
  return out;
}

// The cube experiments one by one (`all` adds the FEM beams, tested in paper_beam_test on a
// small beam: the full size takes minutes under the sanitizers).
TEST(PaperCommand, WritesBothCsvsWithTheContractColumns) {
  const auto dir = std::filesystem::path(VDMSIM_BUILD_DIR) / "test-output" / "paper_cmd";
  std::filesystem::remove_all(dir);
  std::ostringstream out, err;
  ASSERT_EQ(cmd_paper("cube-stress", dir.string(), out, err), 0) << err.str();
  ASSERT_EQ(cmd_paper("anisotropy", dir.string(), out, err), 0) << err.str();
  EXPECT_TRUE(std::filesystem::exists(dir / "cube-stress.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "anisotropy.png"));
  const auto stress = lines_of(dir / "cube-stress.csv");
  ASSERT_FALSE(stress.empty());
  EXPECT_EQ(stress[0], "step,point,sx,sy,sz");
  EXPECT_EQ(stress.size(), 1u + 3u * 31u);
  const auto aniso = lines_of(dir / "anisotropy.csv");
  ASSERT_FALSE(aniso.empty());
  EXPECT_EQ(aniso[0], "case,step,point,ux,uy,uz,volume_rel_error");
  EXPECT_EQ(aniso.size(), 1u + 3u * 3u * 31u);
  EXPECT_EQ(aniso[1].rfind("uniform,0,A,", 0), 0u) << aniso[1];
}

TEST(PaperCommand, UnknownExperimentAndUnwritableFolderExitWith2) {
  std::ostringstream out, err;
  EXPECT_EQ(cmd_paper("cube-stres", "/tmp/x", out, err), 2);
  EXPECT_NE(err.str().find("unknown experiment 'cube-stres'"), std::string::npos) << err.str();
  std::ostringstream err2;
  EXPECT_EQ(cmd_paper("anisotropy", "/proc/vdmsim_cannot_write_here", out, err2), 2);
  EXPECT_NE(err2.str().find("/proc/vdmsim_cannot_write_here"), std::string::npos) << err2.str();
}

}  // namespace
}  // namespace vdmsim
