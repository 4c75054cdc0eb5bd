// The capsule term (docs/model.md, "the capsule"): the membrane converges under mesh
// refinement, the paper's edge weights do not; both keep the volume exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/geometry.hpp"
#include "support/flat_punch.hpp"

namespace vdm {
namespace {

using punch::PunchCase;
using punch::PunchResult;
using punch::run_punch;

void print(const char* what, int cells, const PunchResult& r) {
  std::printf("%s %3d cells (%6d nodes): dent 10 mm %.4f mm, 20 mm %.4f mm; force %.4f N; volume error %.1e\n", what,
              cells, r.nodes, 1e3 * r.dent[0], 1e3 * r.dent[1], r.force, r.volume_error);
}

double relative_change(double coarse, double fine) { return std::abs(fine - coarse) / std::abs(fine); }

TEST(MembraneCapsule, FlatPunchConvergesUnderRefinement) {
  // A square punch of half-width 5 mm, its edges on mesh lines at every resolution: a round
  // punch's footprint on this lattice (the nodes within its radius) changes with the mesh by
  // a share of a cell, an O(h) error of the loading itself that hides the model's.
  PunchCase c;
  c.square = true;
  const std::vector<double> at = {0.010, 0.020};
  const PunchResult r20 = run_punch(c, 20, at), r40 = run_punch(c, 40, at), r80 = run_punch(c, 80, at);
  print("membrane", 20, r20);
  print("membrane", 40, r40);
  print("membrane", 80, r80);
  for (const PunchResult* r : {&r20, &r40, &r80}) EXPECT_LT(std::abs(r->volume_error), 1e-9);
  // The criterion: under 10 % between the two finest meshes, for both dents and the force.
  EXPECT_LT(relative_change(r40.dent[0], r80.dent[0]), 0.10);
  EXPECT_LT(relative_change(r40.dent[1], r80.dent[1]), 0.10);
  EXPECT_LT(relative_change(r40.force, r80.force), 0.10);
  // A dimple, not a pinhole: the surface 2 punch radii out goes down by a share of the depth.
  EXPECT_LT(r80.dent[0], -0.1 * c.depth);
}

TEST(PaperCapsule, FlatPunchDentFadesUnderRefinement) {
  // The paper's literal weights scale with the cell area: the dent beside the punch shrinks
  // towards the nodes under it as the mesh is refined (the defect the membrane form mends).
  PunchCase c;
  c.capsule = CapsuleForm::paper;
  const std::vector<double> at = {0.010, 0.020};
  const PunchResult r20 = run_punch(c, 20, at), r40 = run_punch(c, 40, at);
  print("paper   ", 20, r20);
  print("paper   ", 40, r40);
  EXPECT_LT(std::abs(r40.dent[0]), 0.5 * std::abs(r20.dent[0]));
}

}  // namespace
}  // namespace vdm
