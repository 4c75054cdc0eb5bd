#include "app/sweep/summary.hpp"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "render/contact_sheet.hpp"
#include "render/png_io.hpp"
#include "render/views.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string scalar(const YAML::Node& js, const char* key) {
  const YAML::Node n = js[key];
  return n && n.IsScalar() ? n.Scalar() : "";
}

// The largest contact_force_n of metrics.csv's first `frames` rows, as written, and its frame.
void read_contact_force(const fs::path& metrics, int frames, RunResult& r) {
  std::ifstream in(metrics);
  std::string line;
  if (!std::getline(in, line)) return;
  int column = -1, c = 0;
  std::istringstream header(line);
  for (std::string name; std::getline(header, name, ','); ++c)
    if (name == "contact_force_n") column = c;
  if (column < 0) return;
  double best = -1;
  for (int row = 0; row < frames && std::getline(in, line); ++row) {
    std::istringstream fields(line);
    std::string field;
    for (int k = 0; k <= column && std::getline(fields, field, ','); ++k) {
    }
    const double f = std::strtod(field.c_str(), nullptr);
    if (f > best) {
      best = f;
      r.max_contact_force_n = field;
      r.deepest_frame = best > 0 ? row : frames - 1;
    }
  }
}

// The last "vdmsim: error: ..." of a run's log, without the prefix ("" when none).
std::string last_error(const fs::path& log) {
  std::ifstream in(log);
  std::string line, found;
  const std::string prefix = "vdmsim: error: ";
  while (std::getline(in, line))
    if (line.compare(0, prefix.size(), prefix) == 0) found = line.substr(prefix.size());
  return found;
}

std::string label_of(const SweepPlan& plan, const PlannedRun& run, int frame) {
  std::string label = "run " + run.folder.substr(0, run.folder.find('_')) + ", frame " + std::to_string(frame);
  for (size_t k = 0; k < plan.columns.size(); ++k)
    if (!run.values[k].empty()) {
      const std::string& key = plan.columns[k];
      const size_t dot = key.rfind('.');
      label += "\n" + (dot == std::string::npos ? key : key.substr(dot + 1)) + " = " + run.values[k];
    }
  return label;
}

}  // namespace

RunResult read_run_result(const fs::path& dir, const fs::path& slurm_log) {
  RunResult r;
  std::error_code ec;
  if (fs::exists(dir / "run.json", ec)) {
    try {
      const YAML::Node js = YAML::LoadFile((dir / "run.json").string());
      r.status = scalar(js, "status");
      r.reason = scalar(js, "reason");
      r.frames = scalar(js, "frames");
      r.median_step_ms = scalar(js, "median_step_ms");
      r.max_volume_rel_error = scalar(js, "max_volume_rel_error");
      r.wall_time_s = scalar(js, "wall_time_s");
      read_contact_force(dir / "metrics.csv", std::atoi(r.frames.c_str()), r);
      if (r.status != "completed" && r.reason.empty()) r.reason = last_error(dir / "run.log");
      return r;
    } catch (const YAML::Exception& e) {
      r.status = "failed";
      r.reason = (dir / "run.json").string() + ": cannot read: " + e.what();
      return r;
    }
  }
  if (fs::exists(dir / "run.log", ec)) {
    // The run stopped before it had a run.json: a scene or mesh it refused, or it was killed.
    r.status = "failed";
    r.reason = last_error(dir / "run.log");
    if (r.reason.empty()) r.reason = "ended without a result (killed?); see " + (dir / "run.log").string();
    return r;
  }
  r.status = "not run";
  if (!slurm_log.empty() && fs::exists(slurm_log, ec)) r.reason = "no result; see " + slurm_log.string();
  return r;
}

void note_exit_code(RunResult& r, int code, const fs::path& run_dir) {
  if (code <= 0) return;
  if (code == 130) {
    if (r.status == "completed") r.status = "interrupted";
    return;
  }
  if (r.status == "failed") return;
  r.status = "failed";
  const std::string said = last_error(run_dir / "run.log");
  r.reason = "exit " + std::to_string(code) + (said.empty() ? std::string() : ": " + said);
}

std::string summary_csv(const SweepPlan& plan, const std::vector<RunResult>& results) {
  std::ostringstream csv;
  csv << "run,status";
  for (const std::string& c : plan.columns) csv << ',' << csv_field(c);
  csv << ",frames,median_step_ms,max_volume_rel_error,max_contact_force_n,wall_time_s,reason\n";
  for (size_t i = 0; i < plan.runs.size() && i < results.size(); ++i) {
    const RunResult& r = results[i];
    csv << csv_field(plan.runs[i].folder) << ',' << csv_field(r.status);
    for (const std::string& v : plan.runs[i].values) csv << ',' << csv_field(v);
    csv << ',' << r.frames << ',' << r.median_step_ms << ',' << r.max_volume_rel_error << ',' << r.max_contact_force_n
        << ',' << r.wall_time_s << ',' << csv_field(r.reason) << '\n';
  }
  return csv.str();
}

bool write_summary_png(const SweepPlan& plan, const std::vector<RunResult>& results, const fs::path& dir, bool& written,
                       std::string& error) {
  written = false;
  std::vector<render::Thumbnail> thumbs;
  for (size_t i = 0; i < plan.runs.size() && i < results.size(); ++i) {
    if (results[i].deepest_frame < 0) continue;
    const fs::path run = dir / "runs" / plan.runs[i].folder;
    render::Image image;
    std::string ignored;
    bool found = false;  // the frame of the first picture view the run drew
    for (const render::ViewRow& row : render::view_table())
      if (!found && row.pass == render::ViewPass::picture)
        found = render::read_png((run / row.folder / render::view_file_name(row, results[i].deepest_frame)).string(),
                                 image, ignored);
    if (!found) continue;  // not rendered
    render::Thumbnail t;
    t.frame = results[i].deepest_frame;
    t.image = render::downscale(image, std::max(1, image.width / 320));
    t.label = label_of(plan, plan.runs[i], t.frame);
    thumbs.push_back(std::move(t));
  }
  if (thumbs.empty()) return true;
  const std::string title = plan.sweep_file.filename().string() + ": the deepest-contact frame of each run";
  if (!render::write_contact_sheet(thumbs, title, (dir / "summary.png").string(), 6, error)) return false;
  written = true;
  return true;
}

}  // namespace vdmsim
