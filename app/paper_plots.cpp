#include "app/paper_plots.hpp"

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

}  // namespace vdmsim
