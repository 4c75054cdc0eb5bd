// Where the commands write (issue 46), through the real binary: an empty --out (an unset
// $OUTDIR) is refused by every command (exit 2) and nothing is written into the current folder;
// a full disk is a failure at run time (exit 1, "no space left") and leaves no probe file.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using vdmsim::test::CliResult;

fs::path output_paths_dir() { return vdmsim::test::scratch_dir("output_paths_cli"); }

bool contains_text(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::set<std::string> listing(const fs::path& d) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(d)) names.insert(e.path().string());
  return names;
}

std::string asset(const std::string& rel) { return (fs::path(VDMSIM_SOURCE_DIR) / "assets" / rel).string(); }

TEST(OutputPathsCli, AnEmptyOutIsRefusedByEveryCommandAndNothingIsWritten) {
  const fs::path cwd = output_paths_dir() / "cwd";
  fs::create_directories(cwd);
  fs::create_directories(cwd / "out");
  const std::string scene = asset("scenes/liver_press.yaml"), mesh = asset("meshes/liver_L4.obj");
  const std::string commands[] = {
      "run " + scene + " --no-render --frames 1 --out ''",
      "sweep " + asset("sweeps/probe_stiffness.yaml") + " --no-render --frames 1 --out ''",
      "prepare-mesh " + mesh + " --out ''",
      "make-organ liver --out ''",
      "paper cube-stress --out ''",
      "calibrate --mesh " + mesh + " --out ''",
      "bench --quick --only nothing --out ''",
      "accuracy --quick --task 0 --out ''",
      "compare " + scene + " " + scene + " --diff ''",
  };
  const std::set<std::string> before = listing(cwd);
  for (const std::string& command : commands) {
    const CliResult r = vdmsim::test::run_cli("cd " + cwd.string() + " && " + VDMSIM_BINARY, command);
    EXPECT_EQ(r.code, 2) << command << "\n" << r.output;
    EXPECT_TRUE(contains_text(r.output, ": empty: name the file or folder")) << command << "\n" << r.output;
    EXPECT_EQ(listing(cwd), before) << command;
  }
}

// /dev/full fails every write with ENOSPC, as a full disk does: a failure at run time.
TEST(OutputPathsCli, AFileWrittenToAFullDiskIsAFailureAtRunTime) {
  for (const std::string command : {"make-organ liver --level 2 --out /dev/full",
                                    "make-organ liver --level 2 --scan-like --out /dev/full"}) {
    const CliResult r = vdmsim::test::run_cli(VDMSIM_BINARY, command);
    EXPECT_EQ(r.code, 1) << command << "\n" << r.output;
    EXPECT_TRUE(contains_text(r.output, "vdmsim: error: /dev/full: write failed: no space left on the device")) << r.output;
  }
}

// A folder on a full file system (a 64 kB tmpfs, filled, in a mount namespace of the test's own):
// `run` stops before simulating, says so, exits 1 and leaves nothing in the folder.
TEST(OutputPathsCli, AFullDiskIsAFailureAtRunTimeAndLeavesNoProbe) {
  if (vdmsim::test::run_cli("unshare", "-rm true").code != 0)
    GTEST_SKIP() << "cannot make a mount namespace here (unshare -rm): no full disk to test on";
  const fs::path disk = output_paths_dir() / "disk";
  fs::create_directories(disk);
  const std::string script = "mount -t tmpfs -o size=64k tmpfs " + disk.string() + " && (head -c 100000 /dev/zero > " +
                             disk.string() + "/fill) 2>/dev/null; " + VDMSIM_BINARY + " run " +
                             asset("scenes/liver_press.yaml") + " --no-render --frames 2 --out " + disk.string() +
                             "/run; echo \"exit $?\"; echo left:; ls -A " + disk.string() + "/run";
  const CliResult r = vdmsim::test::run_cli("unshare", "-rm sh -c '" + script + "'");
  EXPECT_TRUE(contains_text(r.output, "vdmsim: error: " + disk.string() + "/run: cannot write in the output folder: no space "
                                  "left on the device"))
      << r.output;
  EXPECT_TRUE(contains_text(r.output, "exit 1\n")) << r.output;
  EXPECT_FALSE(contains_text(r.output, ".vdmsim-write-test")) << r.output;
}

}  // namespace
