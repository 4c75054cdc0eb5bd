#include "app/studies/ladder_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "render/plot.hpp"

namespace vdmsim {

namespace {

std::string csv_text(std::string s) {
  std::replace(s.begin(), s.end(), ',', ';');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

// A panel: a case and the measure it plots, and the target for it (relative).
struct LadderPanel {
  const char* test_case;
  bool force;  // the force error (else the case's displacement measure)
  const char* title;
  double target;  // 0: none
};

}  // namespace

const LadderRow* ladder_reference(const std::vector<LadderRow>& rows, const std::string& test_case) {
  for (const LadderRow& r : rows)
    if (r.config.reference && r.config.test_case == test_case && !r.failed) return &r;
  return nullptr;
}

bool write_ladder_csv(const std::string& path, const std::vector<LadderRow>& rows, std::string& error) {
  std::ofstream f(path);
  f << "scenario,case,model,reference,resolution,nodes,median_ms,measured_median_ms,yardstick_ms,time_vs_reference,"
       "error,force_error,volume_rel_error,detail,folder,note\n";
  f << std::setprecision(6);
  for (const LadderRow& r : rows) {
    const LadderConfig& c = r.config;
    f << c.scenario << ',' << c.test_case << ',' << to_string(c.model) << ',' << (c.reference ? 1 : 0) << ','
      << csv_text(ladder_resolution(c)) << ',';
    if (r.failed) {
      f << ",,,,,,,,";
    } else {
      const LadderRow* ref = ladder_reference(rows, c.test_case);
      f << r.nodes << ',' << r.median_ms << ',' << r.measured_median_ms << ',' << r.yardstick_ms << ',';
      if (ref && ref->median_ms > 0) f << r.median_ms / ref->median_ms;
      f << ',' << r.error << ',';
      if (r.force_error >= 0) f << r.force_error;
      f << ',' << r.volume_rel_error << ',' << csv_text(r.detail);
    }
    f << ',' << r.folder << ',' << csv_text(r.note) << '\n';
  }
  f.close();
  if (!f) {
    error = path + ": write failed";
    return false;
  }
  return true;
}

bool write_ladder_plot(const std::string& path, const std::vector<LadderRow>& rows, std::string& error) {
  render::Figure fig;
  fig.title = "The model ladder: each model's error against the reference FEM, over its time per step (one run)";
  fig.columns = 3;
  fig.panel_width = 560;
  fig.panel_height = 440;
  const std::vector<LadderPanel> panels = {
      {"punch", false, "flat punch: the dent (largest error, 1.5-4 radii)", 0.35},
      {"punch", true, "flat punch: the force", 0.30},
      {"liver_probe", false, "liver probe: surface displacement (relative L2)", 0},
      {"stretch", false, "beam stretched 20 %: |u| at A, B, C", 0.10},
      {"bend", false, "beam bent by its width: |u| at A, B, C", 0.15},
      {"twist", false, "beam twisted 30 deg: |u| at A, B, C", 0.30},
  };
  constexpr double kFloor = 1e-3;  // % : an error at round-off still shows on the log axis
  for (const LadderPanel& lp : panels) {
    render::Panel p;
    p.title = lp.title;
    p.x_label = "median time per step (ms, on the study's typical node)";
    p.y_label = std::string(lp.force ? "force" : "displacement") + " error against the reference FEM (%)";
    p.log_x = p.log_y = true;
    double lo = 1e300, hi = 0, t_lo = 1e300, t_hi = 0;
    auto series = [&](LadderModel model, bool reference, const std::string& label, int colour, bool line) {
      render::Series s;
      s.color = colour;
      s.line = line;
      s.markers = true;
      std::vector<const LadderRow*> picked;
      for (const LadderRow& r : rows)
        if (!r.failed && r.config.test_case == lp.test_case && r.config.model == model && r.config.reference == reference)
          picked.push_back(&r);
      // Cheapest first: a line joins the rung's resolutions in order of cost.
      std::sort(picked.begin(), picked.end(), [](const LadderRow* a, const LadderRow* b) { return a->median_ms < b->median_ms; });
      std::string sizes;
      for (const LadderRow* r : picked) {
        const double e = 100 * std::max(lp.force ? r->force_error : r->error, kFloor / 100);
        s.x.push_back(r->median_ms);
        s.y.push_back(e);
        lo = std::min(lo, e);
        hi = std::max(hi, e);
        t_lo = std::min(t_lo, r->median_ms);
        t_hi = std::max(t_hi, r->median_ms);
        if (model == LadderModel::vdm_core) {
          std::ostringstream h;
          h << 1e3 * r->config.cell_size;
          sizes += (sizes.empty() ? "" : " / ") + h.str();
        }
      }
      s.label = model == LadderModel::vdm_core ? label + " (cells " + sizes + " mm)" : label;
      if (!s.x.empty()) p.series.push_back(std::move(s));
    };
    series(LadderModel::vdm_paper, false, "paper's VDM", 1, false);
    series(LadderModel::vdm_membrane, false, "membrane VDM", 3, false);
    series(LadderModel::vdm_core, false, "elastic core", 0, true);
    series(LadderModel::fem, false, "FEM, coarser meshes", 2, true);
    if (p.series.empty()) continue;
    const LadderRow* ref = ladder_reference(rows, lp.test_case);
    if (lp.target > 0) {
      lo = std::min(lo, 100 * lp.target);
      hi = std::max(hi, 100 * lp.target);
    }
    if (ref) {
      // The reference's own time, a vertical line (its error is zero by definition).
      render::Series v;
      v.label = "the reference FEM's time";
      v.color = 6;
      v.dashed = true;
      v.x = {ref->median_ms, ref->median_ms};
      v.y = {std::min(lo / 2, hi / 20), hi * 2};  // a decade at least: two labelled ticks
      t_hi = std::max(t_hi, ref->median_ms);
      p.series.push_back(std::move(v));
    }
    if (lp.target > 0) {
      render::Series t;
      std::ostringstream label;
      label << "target (" << 100 * lp.target << " %)";
      t.label = label.str();
      t.color = 8;
      t.dashed = true;
      t.x = {t_lo / 2, t_hi * 2};
      t.y = {100 * lp.target, 100 * lp.target};
      p.series.push_back(std::move(t));
    }
    fig.panels.push_back(std::move(p));
  }
  if (fig.panels.empty()) {
    error = path + ": no rung of the ladder completed";
    return false;
  }
  return render::write_figure_png(fig, path, error);
}

}  // namespace vdmsim
