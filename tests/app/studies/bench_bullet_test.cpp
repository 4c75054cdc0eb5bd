// The bench's Bullet case (app/studies/bench_bullet.cpp) runs on the 2.5k-node liver with the bench's
// probe and settings: it times frames in contact and measures a volume error. Figures are not
// asserted (speed is for benchmarks); what is checked is that the case does what it says.
#include <gtest/gtest.h>

#include <cmath>

#include "app/studies/bench.hpp"
#include "app/studies/bench_bullet.hpp"

namespace vdmsim {
namespace {

TEST(BenchBullet, ProbeCaseTimesContactFramesAndMeasuresVolume) {
  if (!bullet_available()) GTEST_SKIP() << "this build has no Bullet (libbullet-dev)";
  const PreparedScene ps = bench_probe_scene("liver_L4.obj", 60, false);
  const BulletRun run = run_bullet_probe(ps, 60, 20, BulletSettings{});
  EXPECT_EQ(run.nodes, ps.organ().model.n);
  // The probe reaches the surface at t = 0.5 s (frame 15) and leaves it near t = 3 s.
  EXPECT_GT(run.contact_frames, 20);
  ASSERT_FALSE(run.step_ms.empty());
  for (double ms : run.step_ms) {
    EXPECT_TRUE(std::isfinite(ms));
    EXPECT_GT(ms, 0.0);
  }
  EXPECT_TRUE(std::isfinite(run.volume_rel_error));
  EXPECT_GT(run.volume_rel_error, 0.0);  // a soft body pushed 15 mm does not keep its volume to round-off
  EXPECT_LT(run.volume_rel_error, 1.0);
  // The probe pushes the surface in (15 mm deep in the script; Bullet's links give a little).
  EXPECT_GT(run.max_displacement, 0.005);
  EXPECT_LT(run.max_displacement, 0.03);
}

TEST(BenchBullet, WithoutBulletTheCaseSaysSo) {
  if (bullet_available()) GTEST_SKIP() << "this build has Bullet";
  const PreparedScene ps = bench_probe_scene("liver_L4.obj", 2, false);
  EXPECT_THROW(run_bullet_probe(ps, 2, 0, BulletSettings{}), std::runtime_error);
}

}  // namespace
}  // namespace vdmsim
