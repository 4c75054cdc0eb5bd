// The job array's batch script, for a sweep and for the accuracy study: the array's indices,
// its limit and partition, and the task's command line, which sh runs with each word intact.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "app/sweep/slurm_runner.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

std::vector<RunJob> jobs_at(const std::vector<int>& indices) {
  std::vector<RunJob> jobs;
  for (int i : indices) jobs.push_back({i, "/runs/" + std::to_string(i), RunFolderState::fresh});
  return jobs;
}

TEST(SlurmRunner, ScriptNamesTheArrayItsLimitAndPartition) {
  SlurmArray a;
  a.name = "accuracy";
  a.what = "vdmsim accuracy --out /shared/acc";
  a.task_command = {"/opt/vdmsim/bin/vdmsim", "accuracy", "--out", "/shared/acc", "--quick"};
  a.partition = "short";
  a.max_parallel = 2;
  const std::string script = batch_script(jobs_at({0, 1, 4, 5, 6, 9}), a, "/shared/acc");
  EXPECT_NE(script.find("#SBATCH --job-name=vdmsim-accuracy\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --array=0-1,4-6,9%2\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --partition=short\n"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --output=/shared/acc/slurm/task_%a.out\n"), std::string::npos) << script;
  EXPECT_NE(script.find("exec '/opt/vdmsim/bin/vdmsim' 'accuracy' '--out' '/shared/acc' '--quick' --task \"$SLURM_ARRAY_TASK_ID\"\n"),
            std::string::npos)
      << script;
  // Without --max-parallel, all at once; without --partition, the cluster's default.
  a.max_parallel = 0;
  a.partition.clear();
  const std::string all = batch_script(jobs_at({3, 4, 5}), a, "/shared/acc");
  EXPECT_NE(all.find("#SBATCH --array=3-5%3\n"), std::string::npos) << all;
  EXPECT_EQ(all.find("--partition"), std::string::npos) << all;
}

TEST(SlurmRunner, TheTaskGetsEveryWordAsWrittenAndItsIndex) {
  // The script run by sh as a task would be, its command a program that prints its arguments.
  const fs::path d = test::scratch_dir("slurm_runner");
  SlurmArray a;
  a.name = "sweep";
  a.what = "a test";
  a.task_command = {"printf", "[%s]", "a folder with spaces", "it's", "$HOME"};
  std::ofstream(d / "task.sbatch") << batch_script(jobs_at({7}), a, d);
  const test::CliResult r = test::run_cli("SLURM_ARRAY_TASK_ID=7 sh", (d / "task.sbatch").string());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output, "[a folder with spaces][it's][$HOME][--task][7]");
}

TEST(SlurmRunner, TheSweepsArrayCarriesItsOptions) {
  SweepOptions o;
  o.sweep_file = "/s/stiff.yaml";
  o.frames = 30;
  o.render = false;
  o.video = true;
  o.partition = "long";
  o.max_parallel = 50;
  const SlurmArray a = sweep_array(o, "/shared/out");
  EXPECT_EQ(a.name, "sweep");
  ASSERT_GE(a.task_command.size(), 9u);
  EXPECT_EQ(std::vector<std::string>(a.task_command.begin() + 1, a.task_command.end()),
            (std::vector<std::string>{"sweep", "/s/stiff.yaml", "--out", "/shared/out", "--frames", "30", "--no-render", "--video"}));
  EXPECT_EQ(a.partition, "long");
  EXPECT_EQ(a.max_parallel, 50);
}

}  // namespace
}  // namespace vdmsim
