// `vdmsim accuracy` on the sweep machinery, through the binary, on a small quick set (the probe
// poke: reference, baseline, two tolerances, one refresh period): the same accuracy columns
// with --jobs 1 and --jobs 2 and on a real Slurm cluster (skipped where none answers); a rerun
// that simulates nothing; a study stopped with Ctrl-C that continues to the same columns; one
// configuration alone with --task; bad options named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace fs = std::filesystem;
using vdmsim::test::run_cli;

namespace {

const std::string kSmallSet = " --quick --scenario probe_poke --only tolerance,refresh";

fs::path dir() { return vdmsim::test::scratch_dir("accuracy_command"); }

using Row = std::map<std::string, std::string>;

std::vector<Row> read_csv(const fs::path& csv) {
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> lines;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> fields(1);
    for (char c : line) {
      if (c == ',') fields.emplace_back();
      else fields.back() += c;
    }
    lines.push_back(fields);
  }
  std::vector<Row> rows;
  for (size_t r = 1; r < lines.size(); ++r) {
    Row row;
    for (size_t c = 0; c < lines[0].size() && c < lines[r].size(); ++c) row[lines[0][c]] = lines[r][c];
    rows.push_back(row);
  }
  return rows;
}

// The rows without the columns that are times or follow from them (the Pareto front).
std::vector<Row> accuracy_columns(std::vector<Row> rows) {
  for (Row& r : rows)
    for (const char* time : {"median_ms", "p95_ms", "measured_median_ms", "yardstick_ms", "pareto"}) r.erase(time);
  return rows;
}

std::string text_of(const fs::path& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

vdmsim::test::CliResult study(const fs::path& out, const std::string& more) {
  return run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + kSmallSet + more);
}

// The small set's rows make physical sense: the reference exact, the others close to it but
// not equal, the volume kept, every scene in its run folder.
void expect_sensible(const std::vector<Row>& rows, const fs::path& out) {
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0].at("varied"), "reference");
  EXPECT_EQ(std::stod(rows[0].at("rms_error_mm")), 0.0);
  for (size_t k = 1; k < rows.size(); ++k) {
    const Row& r = rows[k];
    ASSERT_FALSE(r.at("rms_error_mm").empty()) << r.at("scene") << ": " << r.at("note");
    EXPECT_GT(std::stod(r.at("rms_error_mm")), 0.0) << r.at("scene");  // a coarser mesh than the reference's
    EXPECT_LT(std::stod(r.at("rms_error_mm")), 1.0) << r.at("scene");
    EXPECT_LT(std::abs(std::stod(r.at("volume_rel_error"))), 1e-4) << r.at("scene");
    EXPECT_GT(std::stod(r.at("yardstick_ms")), 0.0) << r.at("scene");
    EXPECT_TRUE(fs::exists(out / r.at("scene"))) << r.at("scene");
  }
}

bool slurm_answers(std::string& said) {
  const vdmsim::test::CliResult r = run_cli("timeout 10 sinfo", "-h -o %T");
  said = r.output;
  return r.code == 0 && !r.output.empty();
}

}  // namespace

TEST(AccuracyCommand, SameAccuracyColumnsWithOneOrTwoJobsAndARerunSimulatesNothing) {
  const fs::path one = dir() / "jobs1", two = dir() / "jobs2";
  const auto a = study(one, " --jobs 1");
  ASSERT_EQ(a.code, 0) << a.output;
  EXPECT_NE(a.output.find("5 configurations"), std::string::npos) << a.output;
  const auto b = study(two, " --jobs 2");
  ASSERT_EQ(b.code, 0) << b.output;
  const std::vector<Row> rows = read_csv(two / "accuracy.csv");
  expect_sensible(rows, two);
  EXPECT_EQ(accuracy_columns(rows), accuracy_columns(read_csv(one / "accuracy.csv")));
  // Each configuration's trajectory is bit for bit the same (but for its step times, which are
  // not in the compared columns): the displacement error of every row above agrees exactly.

  // A rerun finds every configuration finished: nothing simulated, no result rewritten.
  const fs::path first = two / "runs" / "000_probe_poke_reference_vdm_L5_structured_tol1e-10_r1_n3";
  ASSERT_TRUE(fs::exists(first / "trajectory.bin")) << b.output;
  const auto written = fs::last_write_time(first / "trajectory.bin");
  const std::string run_json = text_of(first / "run.json");
  const auto again = study(two, " --jobs 2");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("5 finished already, 0 to run"), std::string::npos) << again.output;
  EXPECT_EQ(again.output.find("completed in"), std::string::npos) << again.output;
  EXPECT_EQ(fs::last_write_time(first / "trajectory.bin"), written);
  EXPECT_EQ(text_of(first / "run.json"), run_json);
  EXPECT_EQ(read_csv(two / "accuracy.csv"), rows);  // the times too: the same results read again

  // A configuration's scene changed (here, by hand) runs again, and only it.
  const fs::path tolerance = two / "runs" / "004_probe_poke_tolerance_vdm_L4_structured_tol1e-03_r1_n1";
  ASSERT_TRUE(fs::exists(tolerance / "scene.yaml"));
  std::ofstream(tolerance / "scene.yaml", std::ios::app) << "# edited\n";
  const auto edited = study(two, " --jobs 2");
  ASSERT_EQ(edited.code, 0) << edited.output;
  EXPECT_NE(edited.output.find("4 finished already, 1 to run"), std::string::npos) << edited.output;
  EXPECT_EQ(accuracy_columns(read_csv(two / "accuracy.csv")), accuracy_columns(rows));
}

TEST(AccuracyCommand, CtrlCStopsAndTheRerunContinuesToTheSameColumns) {
  const fs::path whole = dir() / "whole", out = dir() / "stopped";
  const auto ref = study(whole, " --jobs 1");
  ASSERT_EQ(ref.code, 0) << ref.output;
  // Stopped once the first configuration (the reference) has its result.
  const fs::path log = dir() / "stopped.log";
  const pid_t pid = vdmsim::test::spawn_quiet(
      {VDMSIM_BINARY, "accuracy", "--out", out.string(), "--quick", "--scenario", "probe_poke", "--only", "tolerance,refresh",
       "--jobs", "1"},
      log.string());
  ASSERT_NE(pid, 0);
  const int code = vdmsim::test::interrupt_once_exists(
      pid, out / "runs" / "000_probe_poke_reference_vdm_L5_structured_tol1e-10_r1_n3" / "run.json", 300);
  const std::string said = text_of(log);
  EXPECT_EQ(code, 130) << said;
  EXPECT_NE(said.find("accuracy: stopped"), std::string::npos) << said;
  EXPECT_FALSE(fs::exists(out / "accuracy.csv")) << said;
  // Again: the finished configurations are kept, the others run.
  const auto again = study(out, " --jobs 1");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(again.output.find(" 0 finished already"), std::string::npos) << again.output;
  EXPECT_EQ(again.output.find("5 finished already"), std::string::npos) << again.output;
  EXPECT_EQ(accuracy_columns(read_csv(out / "accuracy.csv")), accuracy_columns(read_csv(whole / "accuracy.csv")));
}

TEST(AccuracyCommand, SlurmJobArrayGivesTheLocalAccuracyColumns) {
  std::string said;
  if (!slurm_answers(said))
    GTEST_SKIP() << "no Slurm cluster answers here (sinfo: " << said << "); .ci/start_slurm starts one";
  const fs::path local = dir() / "local", cluster = dir() / "cluster";
  const auto a = study(local, " --jobs 2");
  ASSERT_EQ(a.code, 0) << a.output;
  const auto b = study(cluster, " --slurm --max-parallel 2");
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_NE(b.output.find("submitted 5 runs as Slurm job array"), std::string::npos) << b.output;
  // The array's indices are the configurations' in the whole quick study.
  const std::string script = text_of(cluster / "slurm" / "accuracy.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-1,4-6%2"), std::string::npos) << script;
  EXPECT_NE(script.find("'accuracy' '--out'"), std::string::npos) << script;
  const std::vector<Row> rows = read_csv(cluster / "accuracy.csv");
  expect_sensible(rows, cluster);
  EXPECT_EQ(accuracy_columns(rows), accuracy_columns(read_csv(local / "accuracy.csv")));
  // A rerun submits nothing.
  const auto c = study(cluster, " --slurm");
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_EQ(c.output.find("submitted"), std::string::npos) << c.output;
}

TEST(AccuracyCommand, TaskRunsOneConfigurationOnlyAndBadOptionsAreNamed) {
  const fs::path out = dir() / "task";
  // The quick baseline of the probe poke (configuration 1): the study's set-up, then the task.
  const auto setup = run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + " --quick --task 1");
  ASSERT_EQ(setup.code, 0) << setup.output;
  const fs::path baseline = out / "runs" / "001_probe_poke_baseline_vdm_L4_structured_tol1e-08_r1_n1";
  EXPECT_TRUE(fs::exists(baseline / "trajectory.bin")) << setup.output;
  EXPECT_NE(text_of(baseline / "run.json").find("\"status\": \"completed\""), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "accuracy.csv"));
  EXPECT_EQ(std::distance(fs::directory_iterator(out / "runs"), fs::directory_iterator()), 1);
  const auto again = run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + " --quick --task 1");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("finished already"), std::string::npos) << again.output;

  const auto beyond = run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + " --quick --task 99");
  EXPECT_EQ(beyond.code, 2);
  EXPECT_NE(beyond.output.find("--task 99: the study has"), std::string::npos) << beyond.output;
  const auto knob = run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + " --quick --only tolerance,meshes");
  EXPECT_EQ(knob.code, 2);
  EXPECT_NE(knob.output.find("--only: unknown knob 'meshes'"), std::string::npos) << knob.output;
  const auto scenario = run_cli(VDMSIM_BINARY, "accuracy --out " + out.string() + " --scenario liver");
  EXPECT_EQ(scenario.code, 2);
  EXPECT_NE(scenario.output.find("--scenario: unknown scenario 'liver'"), std::string::npos) << scenario.output;
}
