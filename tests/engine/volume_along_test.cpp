// The volume and its slope along a move, in one pass: against enclosed_volume(), the area
// vectors, a central difference and an analytic scaling.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/volume_along.hpp"

namespace vdm {
namespace {

// A deformed sphere off the origin and a move that is nothing special.
struct Moved {
  SurfaceMesh surface;
  NodeMat d;
};
Moved deformed_sphere() {
  Moved m{make_icosphere(0.05, 3), NodeMat()};
  NodeMat& x = m.surface.positions;
  m.d.resize(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    x.row(i) = Vec3(0.3 + 1.2 * x(i, 0), -0.1 + x(i, 1) * (1 + 3 * x(i, 2)), 0.2 + x(i, 2));
    m.d.row(i) = Vec3(std::sin(7.0 * double(i)), 0.4 * std::cos(3.0 * double(i)), x(i, 0) - 0.3) * 0.02;
  }
  return m;
}

TEST(VolumeAlong, VolumeIsEnclosedVolumeAndSlopeIsTheAreaVectorsAlongTheMove) {
  const Moved m = deformed_sphere();
  const Vec3 origin(0.3, -0.1, 0.2);
  std::vector<double> packed;
  const VolumeAlong v = volume_along(m.surface.positions, m.d, nullptr, m.surface.triangles, origin, packed);
  // The same sum: a step with nothing to correct reports the volume a refresh would.
  EXPECT_EQ(v.volume, enclosed_volume(m.surface.positions, m.surface.triangles, origin));
  NodeMat A(m.surface.node_count(), 3);
  distributed_area_vectors(m.surface.positions, m.surface.triangles, A);
  const double slope = (A.array() * m.d.array()).sum();
  EXPECT_NEAR(v.slope, slope, 1e-12 * std::abs(slope));
  // And the slope of the volume actually measured along the move (central difference: the
  // volume is a cubic in t, so the error is h^2 times its cubic term).
  const double h = 1e-3;
  const double up = enclosed_volume(m.surface.positions + h * m.d, m.surface.triangles, origin);
  const double down = enclosed_volume(m.surface.positions - h * m.d, m.surface.triangles, origin);
  EXPECT_NEAR(v.slope, (up - down) / (2 * h), 1e-6 * std::abs(slope));
}

TEST(VolumeAlong, UniformScalingHasSlopeThreeTimesTheVolume) {
  // x + t (x - o) scales the box by 1 + t about o: V(t) = V (1 + t)^3, V'(0) = 3 V.
  const SurfaceMesh box = make_box(Vec3(0.2, 0.3, 0.5), 3, 4, 5);
  NodeMat d = box.positions;
  d.rowwise() -= Vec3(0.01, -0.02, 0.03).transpose();
  std::vector<double> packed;
  const VolumeAlong v = volume_along(box.positions, d, nullptr, box.triangles, Vec3::Zero(), packed);
  EXPECT_NEAR(v.volume, 0.03, 1e-14 * 0.03);
  EXPECT_NEAR(v.slope, 0.09, 1e-14 * 0.09);
}

TEST(VolumeAlong, FrozenEntriesDoNotMove) {
  const Moved m = deformed_sphere();
  FlagMat frozen = FlagMat::Zero(m.d.rows(), 3);
  NodeMat d0 = m.d;
  for (Eigen::Index i = 0; i < m.d.rows(); i += 3) {
    frozen(i, i % 3) = 1;
    d0(i, i % 3) = 0.0;
  }
  std::vector<double> packed;
  const TriMat& t = m.surface.triangles;
  const VolumeAlong a = volume_along(m.surface.positions, m.d, &frozen, t, Vec3::Zero(), packed);
  const VolumeAlong b = volume_along(m.surface.positions, d0, nullptr, t, Vec3::Zero(), packed);
  EXPECT_EQ(a.volume, b.volume);
  EXPECT_EQ(a.slope, b.slope);
  EXPECT_NE(a.slope, volume_along(m.surface.positions, m.d, nullptr, t, Vec3::Zero(), packed).slope);
}

}  // namespace
}  // namespace vdm
