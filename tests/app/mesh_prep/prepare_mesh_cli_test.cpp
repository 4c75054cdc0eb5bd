// vdmsim prepare-mesh through the real binary (issue 46): it never overwrites its input, refuses
// at once an edge that would remesh for hours, refuses --nodes 0 and --edge-length 0 as it
// refuses --nodes 1, and a full disk is a failure at run time (exit 1, "no space left").
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "app/scene/mesh_io.hpp"
#include "engine/shapes.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;

fs::path dir() { return vdmsim::test::scratch_dir("prepare_mesh_cli"); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A 10 cm ball (radius 0.05 m: 0.0314 m^2), the scan the tests prepare.
std::string ball(const std::string& name) {
  const fs::path p = dir() / name;
  std::string error;
  EXPECT_TRUE(vdmsim::save_obj(vdm::make_icosphere(0.05, 3), p.string(), "a scan", error)) << error;
  return p.string();
}

// prepare-mesh ARGS, stopped after 60 s (a hang fails the test instead of blocking it).
CliResult prepare(const std::string& args) {
  return vdmsim::test::run_cli("timeout", std::string("60 ") + VDMSIM_BINARY + " prepare-mesh " + args);
}

TEST(PrepareMeshCli, TheOutputBeingTheInputIsRefusedAndTheScanKept) {
  const std::string scan = ball("scan.obj");
  const std::string original = bytes(scan);
  fs::create_symlink(scan, dir() / "link.obj");
  fs::create_hard_link(scan, dir() / "hard.obj");
  const fs::path sub = dir() / "sub";
  fs::create_directories(sub);
  const std::string other_spelling = (sub / ".." / "scan.obj").string();
  for (const std::string& out : {scan, other_spelling, (dir() / "link.obj").string(), (dir() / "hard.obj").string()}) {
    const CliResult r = prepare(scan + " --out " + out + " --nodes 200");
    EXPECT_EQ(r.code, 2) << out << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "vdmsim: error: --out " + out + " is the input " + scan)) << r.output;
    EXPECT_EQ(bytes(scan), original) << out;
  }
}

TEST(PrepareMeshCli, AnEdgeGivingMoreThanAMillionNodesIsRefusedAtOnce) {
  const std::string scan = ball("ball.obj");
  for (const std::string edge : {"1e-09", "0.0001"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const CliResult r = prepare(scan + " --out " + (dir() / "fine.obj").string() + " --edge-length " + edge);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, 2) << edge << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "vdmsim: error: --edge-length " + edge + " m over the surface's"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "nodes, more than 1000000: give at least")) << r.output;
    EXPECT_LT(seconds, 20) << edge;
    EXPECT_FALSE(fs::exists(dir() / "fine.obj"));
  }
}

TEST(PrepareMeshCli, ZeroNodesAndZeroEdgeAreRefusedLikeOneNodeAndANegativeEdge) {
  const std::string scan = ball("zero.obj");
  const std::string out = " --out " + (dir() / "never.obj").string();
  for (const char* option : {"--nodes 0", "--nodes 1", "--nodes -5", "--nodes 2000000"}) {
    const CliResult r = prepare(scan + out + " " + option);
    EXPECT_EQ(r.code, 2) << option << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "--nodes: ")) << r.output;
    EXPECT_TRUE(contains(r.output, "from 100 to 1000000")) << r.output;
  }
  for (const char* option : {"--edge-length 0", "--edge-length -0.01", "--edge-length nan"}) {
    const CliResult r = prepare(scan + out + " " + option);
    EXPECT_EQ(r.code, 2) << option << "\n" << r.output;
    EXPECT_TRUE(contains(r.output, "--edge-length: expected a number above 0")) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir() / "never.obj"));
}

// /dev/full fails every write with ENOSPC, as a full disk does.
TEST(PrepareMeshCli, AFullDiskIsAFailureAtRunTimeSayingNoSpaceLeft) {
  const std::string scan = ball("full.obj");
  const CliResult r = prepare(scan + " --out /dev/full --nodes 300");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "vdmsim: error: /dev/full: write failed: no space left on the device")) << r.output;
}

// A failed write leaves the file that was there as it was.
TEST(PrepareMeshCli, AFailedWriteKeepsTheEarlierOutput) {
  const std::string scan = ball("keep.obj");
  const fs::path out = dir() / "kept.obj";
  std::ofstream(out) << "# the earlier result\n";
  // A file-size limit of 0 fails every write the way a full disk does (EFBIG).
  const CliResult r = vdmsim::test::run_cli(
      "sh", "-c 'ulimit -f 0; trap \"\" XFSZ; exec " + std::string(VDMSIM_BINARY) + " prepare-mesh " + scan + " --out " +
                out.string() + " --nodes 300'");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, out.string() + ": write failed: ")) << r.output;
  EXPECT_EQ(bytes(out), "# the earlier result\n");
  EXPECT_FALSE(fs::exists(out.string() + ".tmp"));
}

}  // namespace
