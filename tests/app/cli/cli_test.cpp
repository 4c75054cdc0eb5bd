// The vdmsim executable as a user runs it: output, exit codes, messages.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>
#include <sys/wait.h>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

vdmsim::test::CliResult run_cli(const std::string& args) { return vdmsim::test::run_cli(VDMSIM_BINARY, args); }

TEST(Cli, MeshInfoOnTheSharedLiver) {
  const std::filesystem::path p = std::filesystem::path(VDMSIM_SHARED_ASSETS) / "organs/liver-smooth.obj";
  if (!std::filesystem::exists(p)) GTEST_SKIP() << "shared assets absent (" << p << "): skipping";
  const vdmsim::test::CliResult r = run_cli("mesh-info " + p.string());
  // The surface folds over itself near (-2.1, 4.0, -1.0): no valid organ, the triangles named.
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("crossings:  7 pairs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("triangles 811 and 1958"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("valid organ: no"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("prepare-mesh"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("nodes:      2194"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("closed:     yes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("volume:     39.267"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("bbox size:  6.38"), std::string::npos) << r.output;
}

TEST(Cli, MissingMeshExitsWith2AndNamesTheFile) {
  const vdmsim::test::CliResult r = run_cli("mesh-info /nonexistent/organ.obj");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("/nonexistent/organ.obj: no such file"), std::string::npos) << r.output;
}

TEST(Cli, OpenMeshIsReportedNotClosedWithExit2) {
  const auto p = vdmsim::test::scratch_dir("cli") / "open.obj";
  {
    FILE* f = fopen(p.c_str(), "w");
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n", f);
    fclose(f);
  }
  const vdmsim::test::CliResult r = run_cli("mesh-info " + p.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("closed:     no"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("open surface"), std::string::npos) << r.output;
}

TEST(Cli, UsageErrorsExitWith2) {
  EXPECT_EQ(run_cli("").code, 2);
  EXPECT_EQ(run_cli("frobnicate").code, 2);
  EXPECT_EQ(run_cli("paper anisotropy").code, 2);  // --out is required
  EXPECT_EQ(run_cli("--help").code, 0);
}

// docs/cli.md's exit codes, for every command `vdmsim --help` lists: a usage error is 2, with a
// message (a full disk's 1 is in output_paths_cli_test and prepare_mesh_cli_test).
TEST(Cli, EveryCommandGives2ForAUsageError) {
  const std::string help = run_cli("--help").output;
  std::istringstream lines(help.substr(help.find("Subcommands:")));
  std::string line, name;
  int commands = 0;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    if (line.rfind("  ", 0) != 0 || !(words >> name)) continue;
    const vdmsim::test::CliResult r = run_cli(name + " --no-such-option");
    EXPECT_EQ(r.code, 2) << name << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("vdmsim: ", 0), 0u) << name << "\n" << r.output;
    ++commands;
  }
  EXPECT_GE(commands, 12) << help;
}

// Issue 46: option values out of range are said in the option's own terms (not CLI11's "not in
// range 0.000000 to" a 309-digit number; not "At least 3 required but received 2" for -inf).
TEST(Cli, OptionValuesOutOfRangeAreSaidInTheOptionsTerms) {
  const std::string sweep = std::string(VDMSIM_SOURCE_DIR) + "/assets/sweeps/probe_stiffness.yaml";
  const std::string mesh = std::string(VDMSIM_SOURCE_DIR) + "/assets/meshes/liver_L4.obj";
  const struct {
    std::string args, said;
  } cases[] = {
      {"sweep " + sweep + " --out x --jobs 0", "vdmsim: --jobs: 0 is out of range: from 1 to 100000"},
      {"sweep " + sweep + " --out x --task -1", "vdmsim: --task: -1 is out of range: from 0 to 1000000"},
      {"sweep " + sweep + " --out x --jobs 2.5", "vdmsim: --jobs: expected a whole number from 1 to 100000, got '2.5'"},
      {"accuracy --jobs 0", "vdmsim: --jobs: 0 is out of range: from 1 to 100000"},
      {"accuracy --task -1", "vdmsim: --task: -1 is out of range: from 0 to 1000000"},
      {"run x.yaml --checkpoint-every 0", "vdmsim: --checkpoint-every: 0 is out of range: from 1 to 10000000"},
      {"locate " + mesh + " --from 0 0 1 --toward 0 0 -inf", "vdmsim: error: --toward: -inf is not a finite number"},
      {"locate " + mesh + " --from -nan 0 1 --toward 0 0 -1", "vdmsim: error: --from: -nan is not a finite number"},
  };
  for (const auto& c : cases) {
    const vdmsim::test::CliResult r = run_cli(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.said), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.find("0.000000"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("required but received"), std::string::npos) << r.output;
  }
}

}  // namespace

// Deterministic by default: two runs of an example scene, as a user starts them, write the
// same PNG bytes (the HUD's wall-clock step time is opt-in).
TEST(Cli, TwoDefaultRunsOfAnExampleSceneGiveIdenticalPngs) {
  const std::filesystem::path scene = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/scenes/probe_poke.yaml";
  const std::filesystem::path dir = vdmsim::test::scratch_dir("deterministic_run");
  std::vector<std::filesystem::path> outs = {dir / "a", dir / "b"};
  for (const auto& out : outs) {
    const vdmsim::test::CliResult r = run_cli("run " + scene.string() + " --frames 3 --out " + out.string());
    ASSERT_EQ(r.code, 0) << r.output;
  }
  int compared = 0;
  for (const char* view : {"frames/frame_", "stress/stress_"})
    for (int f = 0; f < 3; ++f) {
      char name[64];
      std::snprintf(name, sizeof name, "%s%05d.png", view, f);
      std::ifstream a(outs[0] / name, std::ios::binary), b(outs[1] / name, std::ios::binary);
      ASSERT_TRUE(a && b) << name;
      const std::string bytes_a((std::istreambuf_iterator<char>(a)), {}), bytes_b((std::istreambuf_iterator<char>(b)), {});
      EXPECT_FALSE(bytes_a.empty()) << name;
      EXPECT_TRUE(bytes_a == bytes_b) << name << " differs between two runs";
      ++compared;
    }
  EXPECT_EQ(compared, 6);
}

// vdmsim calibrate on the project's 2.5k-node liver: progress on the way (the FEM cases and each
// VDM run), a material block written, the E, nu rule's residual printed beside the fit's.
TEST(Cli, CalibrateReportsProgressAndWritesTheMaterial) {
  const std::filesystem::path mesh = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj";
  const std::filesystem::path out = vdmsim::test::scratch_dir("calibrate_cli") / "material.yaml";
  const vdmsim::test::CliResult r = run_cli("calibrate --mesh " + mesh.string() + " --steps 2 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("calibrate: FEM case 1 of 2 (press) done"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("calibrate: FEM case 2 of 2 (pull) done"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("calibrate: VDM run 20:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the E, nu rule"), std::string::npos) << r.output;
  std::ifstream in(out);
  const std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(yaml.find("material: {bulk_modulus: "), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("connectivity_modulus: "), std::string::npos) << yaml;
}
