#include "app/studies/bench_scanned_liver.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "app/mesh_prep/prepare_mesh.hpp"
#include "app/scene/mesh_io.hpp"

namespace fs = std::filesystem;

namespace vdmsim {

std::string scanned_liver_press_scene(const fs::path& shared_assets, const fs::path& out_dir, std::string& why_not) {
  const fs::path dir = fs::absolute(out_dir);  // the scene names its mesh by its whole path
  const fs::path scan = shared_assets / "organs" / "liver-smooth.obj";
  if (!fs::exists(scan)) {
    why_not = "no " + scan.string() + " (SOFA's scanned liver, third-party: not shipped; --shared-assets DIR)";
    return "";
  }
  PrepareMeshOptions opt;
  opt.in = scan.string();
  opt.out = (dir / "scanned_liver.obj").string();
  opt.scale = 0.034;  // its file units to a liver 22 cm across
  opt.nodes = 10000;
  opt.center = true;
  std::ostringstream said;
  if (cmd_prepare_mesh(opt, said, said) != 0) {
    why_not = "prepare-mesh " + scan.string() + ": " + said.str();
    return "";
  }
  const MeshLoadResult mesh = load_surface_mesh(opt.out);
  if (!mesh.ok) {
    why_not = mesh.error;
    return "";
  }
  // The top of the organ under the probe's axis (x = 2 cm, y = 0): the highest node within
  // 5 mm of it; the lowest fifth of the organ rests on the table.
  const auto& x = mesh.mesh.positions;
  double top = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < x.rows(); ++i)
    if (std::abs(x(i, 0) - 0.02) < 0.005 && std::abs(x(i, 1)) < 0.005) top = std::max(top, x(i, 2));
  const double low = x.col(2).minCoeff(), high = x.col(2).maxCoeff();
  if (!std::isfinite(top)) {
    why_not = opt.out + ": no surface above x = 2 cm, y = 0";
    return "";
  }
  const fs::path scene = dir / "scanned_liver_press.yaml";
  std::ofstream f(scene);
  f << "name: scanned_liver_press\n"
    << "organ:\n"
    << "  mesh: " << opt.out << "\n"
    << "  material: {young_modulus: 5000, poisson_ratio: 0.45, density: 1060}\n"
    << "  fixed:\n"
    << "    - {box: {min: [-1, -1, -1], max: [1, 1, " << low + 0.2 * (high - low) << "]}}\n"
    << "simulation:\n"
    << "  frames: 40\n"
    << "  dt: 0.0333333\n"
    << "  effects: [contact]\n"
    << "instruments:\n"
    << "  - type: probe\n"
    << "    radius: 0.004\n"
    << "    length: 0.25\n"
    << "    script:\n"
    << "      - {t: 0.0, tip: [0.02, 0.0, " << top + 0.005 << "], axis: [0, 0, -1]}\n"
    << "      - {t: 0.2, tip: [0.02, 0.0, " << top << "]}\n"
    << "      - {t: 1.0, tip: [0.02, 0.0, " << top - 0.01 << "]}\n"
    << "      - {t: 1.3, tip: [0.02, 0.0, " << top - 0.01 << "]}\n"
    << "render:\n"
    << "  width: 1280\n"
    << "  height: 720\n"
    << "  camera: {eye: [0.15, -0.25, 0.2], target: [0.02, 0.0, 0.03], up: [0, 0, 1], fov_deg: 35}\n"
    << "  views: [shaded]\n";
  f.flush();
  if (!f) {
    why_not = scene.string() + ": write failed";
    return "";
  }
  return scene.string();
}

}  // namespace vdmsim
