// organ.model fem | mass_spring in scenes: validated with positions, built (tets by gmsh,
// the surface kept), and run through the same loop as vdm.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/cli/commands.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/run/scene_run.hpp"
#include "app/simulation/tet_mesher.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

fs::path dir() {
  return vdmsim::test::scratch_dir("organ_models");
}

// A small liver (162 nodes) saved once.
std::string small_liver() {
  const fs::path p = dir() / "liver2.obj";
  if (!fs::exists(p)) {
    std::string error;
    EXPECT_TRUE(save_obj(make_liver_mesh(2), p.string(), "test liver", error)) << error;
  }
  return p.string();
}

std::string scene(const std::string& file, const std::string& model, const std::string& material) {
  const fs::path p = dir() / file;
  std::ofstream(p) << "name: " << fs::path(file).stem().string() << "\n"
                   << "organ:\n  mesh: " << small_liver() << "\n  model: " << model << "\n"
                   << "  material: " << material << "\n"
                   << "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\n"
                   << "  prescribed: [{sphere: {center: [0.035, -0.01, 0.06], radius: 0.04}, translate: [0, 0, -0.01], t: [0, 0.1]}]\n"
                   << "simulation:\n  frames: 3\n  dt: 0.05\n";
  return p.string();
}

std::string problems(const std::string& path, bool& ok) {
  PreparedScene ps;
  std::vector<SceneProblem> list;
  ok = prepare_scene(path, ps, list);
  std::string all;
  for (const auto& p : list) all += p.text() + "\n";
  return all;
}

TEST(OrganModels, BadFemMaterialIsReportedWithItsPosition) {
  bool ok = true;
  std::string msg = problems(scene("nu.yaml", "fem", "{young_modulus: 3000, poisson_ratio: 0.5}"), ok);
  EXPECT_FALSE(ok);
  EXPECT_NE(msg.find("nu.yaml:5:50: organ.material.poisson_ratio: value 0.5 is out of range: expected >= 0 and < 0.5"),
            std::string::npos)
      << msg;
  msg = problems(scene("young.yaml", "fem", "{young_modulus: 0, poisson_ratio: 0.3}"), ok);
  EXPECT_FALSE(ok);
  EXPECT_NE(msg.find("young.yaml:5:29: organ.material.young_modulus: value 0 is out of range: expected > 0"),
            std::string::npos)
      << msg;
  msg = problems(scene("model.yaml", "fen", "{young_modulus: 3000}"), ok);
  EXPECT_FALSE(ok);
  EXPECT_NE(msg.find("model.yaml:4:10: organ.model: unknown model 'fen' (did you mean 'fem'?)"), std::string::npos) << msg;
}

TEST(OrganModels, GmshTetsKeepTheSurface) {
  const vdm::SurfaceMesh s = make_liver_mesh(2);
  vdm::fem::TetMesh t;
  std::string error;
  ASSERT_TRUE(tetrahedralize(s, 0, t, error)) << error;
  ASSERT_EQ(t.surface_nodes, s.node_count());
  EXPECT_EQ((t.positions.topRows(t.surface_nodes) - s.positions).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(t.surface.triangle_count(), s.triangle_count());
  double v = 0;
  for (int k = 0; k < t.tet_count(); ++k)
    v += vdm::fem::tet_volume(t.positions.row(t.tets(k, 0)), t.positions.row(t.tets(k, 1)), t.positions.row(t.tets(k, 2)),
                              t.positions.row(t.tets(k, 3)));
  const double enclosed = vdm::enclosed_volume(s.positions, s.triangles, s.positions.colwise().mean().transpose());
  EXPECT_NEAR(v, enclosed, 1e-9 * enclosed);
}

TEST(OrganModels, GmshBoxWithDiskIsGradedFromTheRim) {
  // The flat punch's reference mesh (tests/app/studies/fem_compare_test.cpp): the disk's rim is
  // a line of the mesh, the surface nodes come first, and the tets are fine at the rim only.
  BoxWithDisk spec;
  spec.h_min = 0.002;
  spec.grade = 0.5;
  spec.h_max = 0.02;
  vdm::fem::TetMesh t;
  std::string error;
  ASSERT_TRUE(mesh_box_with_disk(spec, t, error)) << error;
  double v = 0;
  for (int k = 0; k < t.tet_count(); ++k)
    v += vdm::fem::tet_volume(t.positions.row(t.tets(k, 0)), t.positions.row(t.tets(k, 1)), t.positions.row(t.tets(k, 2)),
                              t.positions.row(t.tets(k, 3)));
  EXPECT_NEAR(v, spec.size.prod(), 1e-9 * spec.size.prod());
  const double top = spec.size.z() / 2;
  int rim = 0, inside = 0;
  for (int i = 0; i < t.surface_nodes; ++i) {
    if (t.positions(i, 2) < top - 1e-12) continue;
    const double r = std::hypot(t.positions(i, 0), t.positions(i, 1));
    rim += std::abs(r - spec.disk_radius) < 1e-9;
    inside += r < spec.disk_radius - 1e-9;
  }
  EXPECT_GE(rim, 12);  // 2 pi R / h_min = 16 edges along it, give or take
  EXPECT_GT(inside, 0);
  // Mean surface edge length near the rim (within 3 mm) and far from it (past 3 cm).
  double near_sum = 0, far_sum = 0;
  int near_n = 0, far_n = 0;
  for (int k = 0; k < t.surface.triangle_count(); ++k)
    for (int c = 0; c < 3; ++c) {
      const vdm::Vec3 a = t.surface.positions.row(t.surface.triangles(k, c)),
                      b = t.surface.positions.row(t.surface.triangles(k, (c + 1) % 3));
      const vdm::Vec3 m = (a + b) / 2;
      const double d = std::hypot(std::hypot(m.x(), m.y()) - spec.disk_radius, m.z() - top);
      if (d < 0.003) near_sum += (a - b).norm(), ++near_n;
      if (d > 0.03) far_sum += (a - b).norm(), ++far_n;
    }
  ASSERT_GT(near_n, 0);
  ASSERT_GT(far_n, 0);
  EXPECT_LT(near_sum / near_n, 0.25 * far_sum / far_n);
  spec.h_max = 0.5 * spec.h_min;
  EXPECT_FALSE(mesh_box_with_disk(spec, t, error));
  EXPECT_NE(error.find("mesh_box_with_disk"), std::string::npos) << error;
}

TEST(OrganModels, FemAndMassSpringScenesRunThroughTheSameLoop) {
  for (const std::string model : {"fem", "mass_spring"}) {
    const std::string path = scene(model + ".yaml", model, "{young_modulus: 3000, poisson_ratio: 0.45, volume_modulus: 20000}");
    PreparedScene ps;
    std::vector<SceneProblem> list;
    ASSERT_TRUE(prepare_scene(path, ps, list)) << (list.empty() ? "" : list[0].text());
    ASSERT_EQ(vdm::to_string(ps.organ().reference.kind), model);
    std::ostringstream out, err;
    RunOptions opt;
    opt.out_dir = (dir() / ("out_" + model)).string();
    ASSERT_EQ(run_scene(ps, opt, out, err, false), 0) << err.str();
    std::ifstream json(fs::path(opt.out_dir) / "run.json");
    std::stringstream js;
    js << json.rdbuf();
    EXPECT_NE(js.str().find("\"model\": \"" + model + "\""), std::string::npos) << js.str();
    // The patch was pushed 10 mm: the largest displacement in the last row is 10 mm.
    std::ifstream csv(fs::path(opt.out_dir) / "metrics.csv");
    std::string line, last;
    while (std::getline(csv, line)) last = line;
    std::vector<std::string> cols;
    std::stringstream ls(last);
    for (std::string c; std::getline(ls, c, ',');) cols.push_back(c);
    ASSERT_GE(cols.size(), 15u) << last;
    EXPECT_NEAR(std::stod(cols[14]), 0.01, 1e-6) << model << ": " << last;
    EXPECT_GT(std::abs(std::stod(cols[6])), 0.0) << model << ": neither keeps the volume exactly";
  }
}

// The largest displacement (metrics.csv's column 14) of every frame of a run.
std::vector<double> largest_displacements(const fs::path& out_dir) {
  std::ifstream csv(out_dir / "metrics.csv");
  std::string line;
  std::vector<double> values;
  std::getline(csv, line);  // header
  while (std::getline(csv, line)) {
    std::vector<std::string> cols;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cols.push_back(c);
    if (cols.size() >= 15) values.push_back(std::stod(cols[14]));
  }
  return values;
}

TEST(OrganModels, CoreSceneWithInertiaSwingsPastItsStaticSag) {
  // A small liver on the elastic core, resting on its underside, its weight switched on at
  // rest: static, every frame shows the settled sag; with the inertia effect it starts from
  // rest, swings past that sag and back (implicit Euler damps the swing).
  std::vector<double> sag[2];
  for (const bool inertia : {false, true}) {
    const fs::path p = dir() / (inertia ? "core_inertia.yaml" : "core_static.yaml");
    std::ofstream(p) << "name: " << p.stem().string() << "\n"
                     << "organ:\n  mesh: " << small_liver() << "\n  model: vdm_core\n  cell_size: 0.01\n"
                     << "  material: {young_modulus: 50000, density: 1060}\n"
                     << "  fixed: [{box: {min: [-1, -1, -1], max: [1, 1, -0.03]}}]\n"
                     << "simulation:\n  frames: 150\n  dt: 0.002\n  effects: [gravity" << (inertia ? ", inertia" : "") << "]\n";
    PreparedScene ps;
    std::vector<SceneProblem> list;
    ASSERT_TRUE(prepare_scene(p.string(), ps, list)) << (list.empty() ? "" : list[0].text());
    std::ostringstream out, err;
    RunOptions opt;
    opt.out_dir = (dir() / ("out_" + p.stem().string())).string();
    ASSERT_EQ(run_scene(ps, opt, out, err, false), 0) << err.str();
    sag[inertia] = largest_displacements(opt.out_dir);
    ASSERT_EQ(sag[inertia].size(), 150u);
  }
  const double settled = sag[0].back();
  ASSERT_GT(settled, 1e-4);
  // (each static step stops within the core's tolerance, 1e-4 of the organ's size: 1 % of
  // this sag)
  EXPECT_NEAR(sag[0][1] / settled, 1.0, 1e-2) << "static: every frame settled";
  EXPECT_LT(sag[1][1], 0.5 * settled) << "with inertia the first frames start from rest";
  const auto peak = std::max_element(sag[1].begin(), sag[1].end());
  EXPECT_GT(*peak, 1.2 * settled) << "it swings past the settled sag";
  EXPECT_LT(*std::min_element(peak, sag[1].end()), *peak - 0.2 * settled) << "and back";
}

}  // namespace
}  // namespace vdmsim
