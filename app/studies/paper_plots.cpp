#include "app/studies/paper_plots.hpp"

#include "render/number_format.hpp"
#include "render/plot.hpp"

namespace vdmsim {
namespace {
// Plate travel at step k, as a percentage of the cube's side.
std::vector<double> compression_axis(const CubeCompression& cfg, size_t steps) {
  std::vector<double> x;
  for (size_t k = 0; k < steps; ++k) x.push_back(100.0 * cfg.compression * double(k) / double(cfg.steps));
  return x;
}
}  // namespace

bool write_cube_stress_plot(const std::string& path, const CubeResult& r, const CubeCompression& cfg, std::string& error) {
  render::Figure f;
  f.title = "Cube compression: stress at A, B, C (paper section 4.1, Fig. 3)";
  f.columns = 3;
  f.panel_width = 520;
  const std::vector<double> x = compression_axis(cfg, r.volume_rel_error.size());
  const char* axis[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d) {
    render::Panel p;
    p.title = std::string("stress along ") + axis[d];
    p.x_label = "compression (% of side)";
    p.y_label = std::string("sigma_") + axis[d] + " (kPa)";
    for (const PointSeries& pt : r.points) {
      render::Series s;
      s.label = pt.name;
      s.x = x;
      for (const vdm::Vec3& v : pt.stress) s.y.push_back(v[d] / 1000.0);
      p.series.push_back(s);
    }
    f.panels.push_back(p);
  }
  return render::write_figure_png(f, path, error);
}

bool write_anisotropy_plot(const std::string& path, const std::vector<AnisotropyCase>& cases,
                           const std::vector<CubeResult>& results, const CubeCompression& cfg, std::string& error) {
  render::Figure f;
  f.title = "Anisotropy: outward displacement of A (top), B (y face), C (x face) (paper section 4.2, Fig. 6)";
  f.columns = 2;
  f.panel_width = 600;
  for (size_t c = 0; c < cases.size(); ++c) {
    const CubeResult& r = results[c];
    render::Panel p;
    p.title = std::string("case: ") + to_string(cases[c]);
    p.x_label = "compression (% of side)";
    p.y_label = "outward displacement (mm)";
    const std::vector<double> x = compression_axis(cfg, r.volume_rel_error.size());
    // Outward normals of the faces the points sit on: A +z (top), B -y, C +x.
    const vdm::Vec3 normal[3] = {vdm::Vec3::UnitZ(), -vdm::Vec3::UnitY(), vdm::Vec3::UnitX()};
    for (size_t k = 0; k < r.points.size() && k < 3; ++k) {
      render::Series s;
      s.label = r.points[k].name;
      s.x = x;
      for (const vdm::Vec3& u : r.points[k].displacement) s.y.push_back(1000.0 * u.dot(normal[k]));
      p.series.push_back(s);
    }
    f.panels.push_back(p);
  }
  render::Panel v;
  v.title = "volume";
  v.x_label = "compression (% of side)";
  v.y_label = "|V - V0| / V0";
  v.log_y = true;
  for (size_t c = 0; c < cases.size(); ++c) {
    render::Series s;
    s.label = to_string(cases[c]);
    s.x = compression_axis(cfg, results[c].volume_rel_error.size());
    for (double e : results[c].volume_rel_error) s.y.push_back(std::abs(e) > 0 ? std::abs(e) : 1e-17);
    s.markers = true;
    s.line = false;
    v.series.push_back(s);
  }
  f.panels.push_back(v);
  return render::write_figure_png(f, path, error);
}

bool write_beam_plot(const std::string& path, const BeamCaseResult& r, std::string& error) {
  render::Figure f;
  f.title = std::string("Beam ") + to_string(r.which) + ": VDM (solid) and FEM (dashed) (paper section 4.3)";
  f.panel_width = 760;
  f.panel_height = 460;
  render::Panel p;
  p.title = "displacement of A, B, C (mean difference " + render::format_number(100 * r.mean_relative_difference, 3) + " %)";
  p.x_label = "step";
  p.y_label = "|u| (mm)";
  const char* names[3] = {"A", "B", "C"};
  for (int k = 0; k < 3; ++k)
    for (int model = 0; model < 2; ++model) {
      const CaseResult& c = model == 0 ? r.vdm : r.fem;
      render::Series s;
      s.label = std::string(names[k]) + (model == 0 ? " VDM" : " FEM");
      s.color = k;
      s.dashed = model == 1;
      for (size_t step = 0; step < c.u.size(); ++step) {
        if (k >= c.u[step].rows()) continue;
        s.x.push_back(double(step));
        s.y.push_back(1000.0 * c.u[step].row(k).norm());
      }
      p.series.push_back(s);
    }
  f.panels.push_back(p);
  return render::write_figure_png(f, path, error);
}

bool write_beam_volume_plot(const std::string& path, const std::vector<BeamCaseResult>& cases, std::string& error) {
  render::Figure f;
  f.title = "Beam volume: VDM (solid) and FEM (dashed)";
  f.panel_width = 760;
  f.panel_height = 460;
  render::Panel p;
  p.title = "volume change";
  p.x_label = "step";
  p.y_label = "(V - V0) / V0 (%)";
  for (size_t k = 0; k < cases.size(); ++k)
    for (int model = 0; model < 2; ++model) {
      const CaseResult& c = model == 0 ? cases[k].vdm : cases[k].fem;
      render::Series s;
      s.label = std::string(to_string(cases[k].which)) + (model == 0 ? " VDM" : " FEM");
      s.color = int(k);
      s.dashed = model == 1;
      for (size_t step = 0; step < c.volume_rel.size(); ++step) {
        s.x.push_back(double(step));
        s.y.push_back(100.0 * c.volume_rel[step]);
      }
      p.series.push_back(s);
    }
  f.panels.push_back(p);
  return render::write_figure_png(f, path, error);
}

}  // namespace vdmsim
