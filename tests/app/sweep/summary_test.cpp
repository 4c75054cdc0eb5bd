// A sweep's summary of its runs (app/sweep/summary): a run whose process failed is never counted
// completed, whatever its folder holds (issue 46: a run left behind by a killed sweep wrote
// "completed" into the folder while this sweep's own run of it was refused).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/sweep/summary.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;

// A run folder whose run.json says completed, and whose run.log says why this sweep's run failed.
fs::path completed_folder(const std::string& name) {
  const fs::path d = vdmsim::test::scratch_dir("summary") / name;
  fs::create_directories(d);
  std::ofstream(d / "run.json") << "{\"status\": \"completed\", \"frames\": 4}\n";
  std::ofstream(d / "run.log") << "vdmsim: error: " << d.string()
                               << ": the folder is in use by another vdmsim run (process 99)\n";
  return d;
}

TEST(Summary, ARunWhoseProcessFailedIsFailedWhateverItsFolderSays) {
  const fs::path d = completed_folder("failed");
  vdmsim::RunResult r = vdmsim::read_run_result(d);
  ASSERT_EQ(r.status, "completed");
  vdmsim::note_exit_code(r, 2, d);
  EXPECT_EQ(r.status, "failed");
  EXPECT_EQ(r.reason, "exit 2: " + d.string() + ": the folder is in use by another vdmsim run (process 99)");
}

TEST(Summary, AStoppedRunIsInterruptedAndASucceedingOneKeepsItsResult) {
  const fs::path d = completed_folder("stopped");
  vdmsim::RunResult r = vdmsim::read_run_result(d);
  vdmsim::note_exit_code(r, 130, d);
  EXPECT_EQ(r.status, "interrupted");
  for (const int code : {0, -1}) {
    vdmsim::RunResult kept = vdmsim::read_run_result(d);
    vdmsim::note_exit_code(kept, code, d);
    EXPECT_EQ(kept.status, "completed") << code;
    EXPECT_EQ(kept.reason, "") << code;
  }
}

}  // namespace
