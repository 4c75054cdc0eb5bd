// The bench's CT-like press scene: made from the shared assets' scanned liver when they are
// there (the probe starts above the organ and ends 1 cm into it), said why not when they are not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "app/scene/mesh_io.hpp"
#include "app/scene/scene.hpp"
#include "app/studies/bench_scanned_liver.hpp"

namespace fs = std::filesystem;

TEST(BenchScannedLiver, WithoutTheSharedAssetsTheCaseSaysWhichFileItLacks) {
  const fs::path dir = fs::temp_directory_path() / "vdmsim_bench_scanned_none";
  fs::create_directories(dir);
  std::string why_not;
  EXPECT_EQ(vdmsim::scanned_liver_press_scene(dir / "no_such_assets", dir, why_not), "");
  EXPECT_NE(why_not.find("no_such_assets/organs/liver-smooth.obj"), std::string::npos) << why_not;
  fs::remove_all(dir);
}

TEST(BenchScannedLiver, ThePressComesDownOnTheOrgansTopAndGoesOneCentimetreIn) {
  const fs::path assets = VDMSIM_SHARED_ASSETS;
  if (!fs::exists(assets / "organs" / "liver-smooth.obj"))
    GTEST_SKIP() << "no " << (assets / "organs" / "liver-smooth.obj").string() << " (../shared is not here)";
  const fs::path dir = fs::temp_directory_path() / "vdmsim_bench_scanned";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string why_not;
  const std::string path = vdmsim::scanned_liver_press_scene(assets, dir, why_not);
  ASSERT_FALSE(path.empty()) << why_not;
  const vdmsim::SceneLoadResult loaded = vdmsim::load_scene(path);
  ASSERT_TRUE(loaded.ok()) << path;
  const vdmsim::MeshLoadResult mesh = vdmsim::load_surface_mesh((dir / "scanned_liver.obj").string());
  ASSERT_TRUE(mesh.ok) << mesh.error;
  EXPECT_GT(mesh.mesh.node_count(), 9000);
  const auto& x = mesh.mesh.positions;
  EXPECT_NEAR(x.col(0).maxCoeff() - x.col(0).minCoeff(), 0.22, 0.01);  // 22 cm across
  // The organ's top under the probe's axis, and the script: 5 mm above it, touching, 1 cm in.
  double top = -1;
  for (int i = 0; i < x.rows(); ++i)
    if (std::abs(x(i, 0) - 0.02) < 0.005 && std::abs(x(i, 1)) < 0.005) top = std::max(top, x(i, 2));
  ASSERT_EQ(loaded.scene.instruments.size(), 1u);
  const auto& script = loaded.scene.instruments[0].script;
  ASSERT_EQ(script.size(), 4u);
  EXPECT_NEAR(script[0].tip->z() - top, 0.005, 1e-6);
  EXPECT_NEAR(script[1].tip->z() - top, 0.0, 1e-6);
  EXPECT_NEAR(script[2].tip->z() - top, -0.01, 1e-6);
  fs::remove_all(dir);
}
