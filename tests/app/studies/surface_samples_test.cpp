// Common surface points across meshes: interpolation that is exact for fields linear in space.
#include <gtest/gtest.h>

#include "app/scene/organ_generator.hpp"
#include "app/studies/surface_samples.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

TEST(SurfaceSamples, CoarseLiverPointsOnAFineLiverInterpolateALinearFieldWithinTheirGap) {
  const vdm::SurfaceMesh coarse = make_liver_mesh(2), fine = make_liver_mesh(4);
  const SurfaceSamples samples(fine, coarse.positions);
  ASSERT_EQ(samples.size(), coarse.positions.rows());
  // The two meshes approximate the same surface: every coarse node lies within a fraction of
  // the fine edge length (~5 mm) of the fine surface.
  EXPECT_LT(samples.max_gap(), 2e-3);
  // u = G X + t on the fine nodes: interpolation at the tied points gives G Y + t where Y is
  // the tied surface point, i.e. within |G| max_gap of the value at the coarse node itself.
  Eigen::Matrix3d G;
  G << 0.01, -0.02, 0.005, 0.0, 0.03, 0.01, -0.01, 0.002, 0.02;
  const vdm::Vec3 t(0.001, -0.002, 0.003);
  const vdm::NodeMat u = (fine.positions * G.transpose()).rowwise() + t.transpose();
  vdm::NodeMat at;
  samples.interpolate(u, at);
  for (int s = 0; s < samples.size(); ++s) {
    const vdm::Vec3 expected = G * coarse.positions.row(s).transpose() + t;
    EXPECT_LT((at.row(s).transpose() - expected).norm(), G.norm() * samples.max_gap() + 1e-15) << s;
  }
}

TEST(SurfaceSamples, PointsAtNodesPickThoseNodes) {
  const vdm::SurfaceMesh ball = vdm::make_icosphere(0.05, 2);
  const SurfaceSamples samples(ball, ball.positions);
  EXPECT_LT(samples.max_gap(), 1e-15);
  vdm::NodeMat u = vdm::NodeMat::Zero(ball.positions.rows(), 3);
  for (int i = 0; i < u.rows(); ++i) u(i, 0) = i;  // a field no interpolation could fake
  vdm::NodeMat at;
  samples.interpolate(u, at);
  for (int i = 0; i < u.rows(); ++i) EXPECT_NEAR(at(i, 0), i, 1e-9) << i;
}

}  // namespace
}  // namespace vdmsim
