// `vdmsim sweep` through the binary: a grid run two at a time, and on a real Slurm cluster with
// the same results; a rerun that simulates nothing; a sweep stopped with Ctrl-C that continues
// to the same results; a failing run reported without stopping the others; the contact force
// growing with the bulk modulus. The scenes are the golden probe (2.5k nodes, a few frames).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/png_io.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace fs = std::filesystem;
using vdmsim::test::run_cli;

namespace {

const std::string kBase = std::string(VDMSIM_SOURCE_DIR) + "/tests/golden/scenes/probe_small.yaml";
const std::string kGrid = "vary:\n  organ.material.young_modulus: [10000, 20000, 40000]\n  instruments[0].radius: [0.006, 0.008]\n";

fs::path dir() { return vdmsim::test::scratch_dir("sweep_run"); }

std::string write_sweep(const std::string& name, const std::string& body) {
  const fs::path file = dir() / name;
  std::ofstream(file) << "base: " << kBase << "\n" << body;
  return file.string();
}

using Row = std::map<std::string, std::string>;

// summary.csv as rows of column -> field (quoted fields unquoted).
std::vector<Row> read_summary(const fs::path& csv, std::vector<std::string>* header = nullptr) {
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> lines;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') fields.back() += '"', ++i;
      else if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) fields.emplace_back();
      else fields.back() += c;
    }
    lines.push_back(fields);
  }
  std::vector<Row> rows;
  if (lines.empty()) return rows;
  if (header) *header = lines[0];
  for (size_t r = 1; r < lines.size(); ++r) {
    Row row;
    for (size_t c = 0; c < lines[0].size() && c < lines[r].size(); ++c) row[lines[0][c]] = lines[r][c];
    rows.push_back(row);
  }
  return rows;
}

// The rows without the columns that are times (they differ from run to run).
std::vector<Row> without_times(std::vector<Row> rows) {
  for (Row& r : rows) {
    r.erase("median_step_ms");
    r.erase("wall_time_s");
  }
  return rows;
}

std::string text_of(const fs::path& p) {
  std::stringstream s;
  s << std::ifstream(p).rdbuf();
  return s.str();
}

// metrics.csv without its step_ms column (the third: a time).
std::string without_step_times(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, out;
  while (std::getline(in, line)) {
    const size_t a = line.find(',', line.find(',') + 1), b = line.find(',', a + 1);
    out += (a == std::string::npos || b == std::string::npos ? line : line.substr(0, a) + line.substr(b)) + "\n";
  }
  return out;
}

// True when a Slurm controller answers (sinfo), with its answer in `said`.
bool slurm_answers(std::string& said) {
  const vdmsim::test::CliResult r = run_cli("timeout 10 sinfo", "-h -o %T");
  said = r.output;
  return r.code == 0 && !r.output.empty();
}

}  // namespace

TEST(Sweep, GridTwoAtATimeThenARerunSimulatesNothing) {
  const std::string sweep = write_sweep("grid.yaml", kGrid);
  const fs::path out = dir() / "grid";
  const auto r = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2 --no-render");
  ASSERT_EQ(r.code, 0) << r.output;
  std::vector<std::string> header;
  const std::vector<Row> rows = read_summary(out / "summary.csv", &header);
  EXPECT_EQ(header, (std::vector<std::string>{"run", "status", "organ.material.young_modulus", "instruments[0].radius", "frames",
                                              "median_step_ms", "max_volume_rel_error", "max_contact_force_n", "wall_time_s",
                                              "reason"}));
  ASSERT_EQ(rows.size(), 6u) << text_of(out / "summary.csv");
  for (const Row& row : rows) {
    EXPECT_EQ(row.at("status"), "completed") << row.at("run") << ": " << row.at("reason");
    EXPECT_EQ(row.at("frames"), "4");
    EXPECT_LT(std::stod(row.at("max_volume_rel_error")), 1e-9);
    // Each run's scene repeats it alone.
    EXPECT_TRUE(fs::exists(out / "runs" / row.at("run") / "scene.yaml")) << row.at("run");
  }
  // The physics through the plumbing: for each probe radius, a stiffer organ pushes back harder.
  for (const std::string radius : {"0.006", "0.008"}) {
    std::vector<double> force;
    for (const Row& row : rows)
      if (row.at("instruments[0].radius") == radius) force.push_back(std::stod(row.at("max_contact_force_n")));
    ASSERT_EQ(force.size(), 3u);
    EXPECT_GT(force[0], 0.1);
    EXPECT_GT(force[1], force[0] * 1.05) << "radius " << radius;
    EXPECT_GT(force[2], force[1] * 1.05) << "radius " << radius;
  }
  // A rerun finds every run finished: nothing simulated, every run's files untouched.
  const fs::path one = out / "runs" / rows[0].at("run");
  const auto run_json_time = fs::last_write_time(one / "run.json");
  const std::string metrics = text_of(one / "metrics.csv");
  const auto again = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2 --no-render");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("6 finished already, 0 to continue, 0 to run"), std::string::npos) << again.output;
  EXPECT_EQ(again.output.find("completed in"), std::string::npos) << again.output;
  EXPECT_EQ(fs::last_write_time(one / "run.json"), run_json_time);
  EXPECT_EQ(text_of(one / "metrics.csv"), metrics);
  EXPECT_EQ(read_summary(out / "summary.csv"), rows);
  // The run's own scene runs alone, from another folder, to the same numbers.
  const fs::path alone = dir() / "alone";
  const auto single = run_cli("cd / && " + std::string(VDMSIM_BINARY),
                              "run " + (one / "scene.yaml").string() + " --out " + alone.string() + " --no-render");
  ASSERT_EQ(single.code, 0) << single.output;
  EXPECT_EQ(text_of(alone / "metrics.csv").substr(0, 200), metrics.substr(0, 200));
}

TEST(Sweep, SlurmJobArrayGivesTheLocalResults) {
  std::string said;
  if (!slurm_answers(said))
    GTEST_SKIP() << "no Slurm cluster answers here (sinfo: " << said << "); .ci/start_slurm starts one";
  const std::string sweep = write_sweep("slurm.yaml", kGrid);
  const fs::path local = dir() / "slurm_local", cluster = dir() / "slurm_cluster";
  const auto a = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + local.string() + " --jobs 2 --no-render");
  ASSERT_EQ(a.code, 0) << a.output;
  const auto b = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + cluster.string() + " --no-render --slurm --max-parallel 2");
  ASSERT_EQ(b.code, 0) << b.output;
  EXPECT_NE(b.output.find("submitted 6 runs as Slurm job array"), std::string::npos) << b.output;
  EXPECT_NE(text_of(cluster / "slurm" / "sweep.sbatch").find("#SBATCH --array=0-5%2"), std::string::npos);
  const std::vector<Row> rows = read_summary(cluster / "summary.csv");
  ASSERT_EQ(rows.size(), 6u) << b.output;
  for (const Row& row : rows) EXPECT_EQ(row.at("status"), "completed") << row.at("run") << ": " << row.at("reason");
  // Deterministic: every value but the times is the same as on this machine.
  EXPECT_EQ(without_times(rows), without_times(read_summary(local / "summary.csv")));
  // A rerun submits nothing.
  const auto c = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + cluster.string() + " --no-render --slurm");
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_EQ(c.output.find("submitted"), std::string::npos) << c.output;
}

TEST(Sweep, CtrlCStopsCleanlyAndTheRerunContinuesToTheSameResults) {
  // Long enough runs (80 frames, a checkpoint every 30) to be stopped in the middle.
  const std::string sweep = write_sweep("stop.yaml", "vary:\n  organ.material.young_modulus: [10000, 20000, 40000]\n");
  const fs::path out = dir() / "stopped", reference = dir() / "unstopped";
  const auto ref = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + reference.string() + " --jobs 2 --no-render --frames 80");
  ASSERT_EQ(ref.code, 0) << ref.output;
  const fs::path log = dir() / "stopped.log";
  const pid_t pid = vdmsim::test::spawn_quiet(
      {VDMSIM_BINARY, "sweep", sweep, "--out", out.string(), "--jobs", "2", "--no-render", "--frames", "80"}, log.string());
  ASSERT_NE(pid, 0);
  const int code = vdmsim::test::interrupt_once_exists(pid, out / "runs" / "000_young_modulus-10000" / "checkpoint.json", 120);
  const std::string stopped_said = text_of(log);
  EXPECT_EQ(code, 130) << stopped_said;
  std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 3u) << stopped_said;
  EXPECT_EQ(rows[0].at("status"), "interrupted") << stopped_said;
  EXPECT_EQ(rows[2].at("status"), "not run") << stopped_said;  // two at a time: the third never started
  // Again: the interrupted runs continue (--resume), the others run; the numbers as if never stopped.
  const auto again = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2 --no-render --frames 80");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("to continue"), std::string::npos);
  EXPECT_NE(text_of(out / "runs" / "000_young_modulus-10000" / "run.json").find("\"resumed_from_frame\""), std::string::npos);
  rows = read_summary(out / "summary.csv");
  EXPECT_EQ(without_times(rows), without_times(read_summary(reference / "summary.csv")));
  // Every frame's numbers, not only the summary's, as in the run that was never stopped.
  for (const std::string run : {"000_young_modulus-10000", "001_young_modulus-20000", "002_young_modulus-40000"}) {
    const std::string got = without_step_times(text_of(out / "runs" / run / "metrics.csv"));
    EXPECT_EQ(std::count(got.begin(), got.end(), '\n'), 81) << run;
    EXPECT_EQ(got, without_step_times(text_of(reference / "runs" / run / "metrics.csv"))) << run;
  }
}

TEST(Sweep, AFailingRunIsReportedAndTheOthersComplete) {
  // An open surface: the run refuses the organ; the runs around it go on.
  std::ofstream(dir() / "open.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n";
  const std::string sweep = write_sweep(
      "failing.yaml", "cases:\n  - {organ.material.young_modulus: 10000}\n  - {organ.mesh: open.obj}\n  - {organ.material.young_modulus: 40000}\n");
  const fs::path out = dir() / "failing";
  const auto r = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2 --no-render");
  EXPECT_EQ(r.code, 1) << r.output;
  const std::vector<Row> rows = read_summary(out / "summary.csv");
  ASSERT_EQ(rows.size(), 3u) << r.output;
  EXPECT_EQ(rows[0].at("status"), "completed");
  EXPECT_EQ(rows[1].at("status"), "failed");
  EXPECT_NE(rows[1].at("reason").find("open surface"), std::string::npos) << rows[1].at("reason");
  EXPECT_EQ(rows[1].at("organ.mesh"), "open.obj");
  EXPECT_EQ(rows[2].at("status"), "completed");
  EXPECT_NE(r.output.find("001_mesh-open.obj: failed: "), std::string::npos) << r.output;
  // A rerun runs the failed run again, and only it.
  const auto again = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2 --no-render");
  EXPECT_EQ(again.code, 1);
  EXPECT_NE(again.output.find("2 finished already, 0 to continue, 1 to run"), std::string::npos) << again.output;
}

TEST(Sweep, RenderedSweepLaysOutEachRunsDeepestContactFrame) {
  const std::string sweep = write_sweep("rendered.yaml", "vary:\n  organ.material.young_modulus: [10000, 40000]\n");
  const fs::path out = dir() / "rendered";
  const auto r = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.output;
  render::Image sheet;
  std::string error;
  ASSERT_TRUE(render::read_png((out / "summary.png").string(), sheet, error)) << error;
  EXPECT_GT(sheet.width, 2 * 320);  // two thumbnails side by side
  EXPECT_TRUE(fs::exists(out / "runs" / "001_young_modulus-40000" / "frames" / "frame_00003.png"));
}

TEST(Sweep, TaskRunsOneRunOnly) {
  const std::string sweep = write_sweep("task.yaml", "vary:\n  organ.material.young_modulus: [10000, 40000]\n");
  const fs::path out = dir() / "task";
  const auto r = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --task 1 --no-render");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "runs" / "001_young_modulus-40000" / "run.json"));
  EXPECT_FALSE(fs::exists(out / "runs" / "000_young_modulus-10000" / "run.json"));
  EXPECT_FALSE(fs::exists(out / "summary.csv"));
  const auto beyond = run_cli(VDMSIM_BINARY, "sweep " + sweep + " --out " + out.string() + " --task 2");
  EXPECT_EQ(beyond.code, 2);
  EXPECT_NE(beyond.output.find("--task 2: the sweep has 2 runs"), std::string::npos) << beyond.output;
}

// Issue 46: a sweep killed with SIGKILL takes its runs with it: none keeps running (and holding
// its folder) for a rerun to collide with.
TEST(Sweep, ASweepKilledTakesItsRunsWithIt) {
  const std::string sweep = write_sweep("killed.yaml", "vary:\n  organ.material.young_modulus: [10000]\n");
  const fs::path out = dir() / "killed";
  const pid_t pid = vdmsim::test::spawn_quiet(
      {VDMSIM_BINARY, "sweep", sweep, "--out", out.string(), "--jobs", "1", "--no-render", "--frames", "100000"});
  ASSERT_NE(pid, 0);
  // The run writes its process id into its folder's lock file once it owns the folder.
  const fs::path lock = out / "runs" / "000_young_modulus-10000" / ".vdmsim.lock";
  pid_t run = 0;
  vdmsim::test::wait_for_file(lock, 60);
  for (int k = 0; k < 6000 && run <= 0; ++k) {
    run = std::atoi(text_of(lock).c_str());
    if (run <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GT(run, 0) << "the run never started";
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  // Gone (or a zombie waiting for init) within 5 s.
  auto alive = [](pid_t p) {
    const std::string stat = text_of("/proc/" + std::to_string(p) + "/stat");
    const size_t paren = stat.rfind(')');
    return paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] != 'Z';
  };
  for (int k = 0; k < 500 && alive(run); ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const bool survived = alive(run);
  if (survived) kill(run, SIGKILL);  // (not to leave it running past the test)
  EXPECT_FALSE(survived) << "vdmsim run " << run << " kept running after its sweep was killed";
}
