// vdm_core's default cell (app/simulation/core_cell.hpp): the organ's volume over its area, no
// wider than the smallest instrument, no finer than the cube bound; a given cell as given.
#include <gtest/gtest.h>

#include <cmath>

#include "app/simulation/core_cell.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

SceneDef core_scene(double probe_radius) {
  SceneDef s;
  s.organ().model = vdm::ModelKind::vdm_core;
  if (probe_radius > 0) {
    tools::InstrumentDef probe;
    probe.type = tools::InstrumentDef::Type::probe;
    probe.radius = probe_radius;
    s.instruments.push_back(probe);
  }
  return s;
}

double cell_of(const SceneDef& s, const vdm::SurfaceMesh& organ) { return core_cell_size(s, s.organ(), organ); }

TEST(CoreCell, DefaultFollowsTheOrganAndTheSmallestInstrument) {
  const vdm::SurfaceMesh ball = vdm::make_icosphere(0.05, 4);
  const double area = vdm::surface_area(ball.positions, ball.triangles);
  const double volume = std::abs(vdm::enclosed_volume(ball.positions, ball.triangles, vdm::Vec3::Zero()));
  // No instrument: V/A (a ball's r / 3).
  EXPECT_NEAR(cell_of(core_scene(0), ball), volume / area, 1e-12);
  EXPECT_NEAR(volume / area, 0.05 / 3, 0.0005);
  // A probe 8 mm across: its width.
  EXPECT_NEAR(cell_of(core_scene(0.004), ball), 0.008, 1e-12);
  // A probe 0.2 mm across: the cube bound, about kDefaultCoreCubes cubes inside the ball.
  const double h = cell_of(core_scene(0.0001), ball);
  EXPECT_GT(h, 0.0002);
  EXPECT_NEAR(volume / (h * h * h), kDefaultCoreCubes, 1e-6 * kDefaultCoreCubes);
  // A given cell is the cell.
  SceneDef given = core_scene(0.004);
  given.organ().cell_size = 0.02;
  EXPECT_EQ(cell_of(given, ball), 0.02);
}

}  // namespace
}  // namespace vdmsim
