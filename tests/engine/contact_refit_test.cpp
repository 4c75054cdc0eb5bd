// The lazy refit of the contact's tree (ContactSettings::lazy_refit) against FCL's refit at
// every query: the narrow phase is exact and the lazy walk keeps exactly the triangles of the
// refitted tree, in the same order, so the runs must agree bit for bit (displacements,
// reactions, contact forces, nodes, solves) in every kind of contact: the bench's probe on
// the 2.5k liver, a probe pressing and sliding (kinematic and penalty), grasper jaws and shaft
// (three tools, opening in contact), each with slacks from none to several edges.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <string>

#include "app/studies/bench.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/contact.hpp"
#include "support/scenarios.hpp"
#include "tools_scripted/instrument.hpp"

namespace vdm {
namespace {

bool same_bits(const NodeMat& a, const NodeMat& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * size_t(a.size())) == 0;
}
bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// Everything a contact step decides, step by step.
struct Record {
  std::vector<NodeMat> u, reaction;
  std::vector<ContactReport> reports;
  void add(const SimState& s, const ContactReport& r) {
    u.push_back(s.u);
    reaction.push_back(s.reaction);
    reports.push_back(r);
  }
};

// `fcl` (refit at every query) against `lazy`, step by step; also that contact happened.
void expect_same(const Record& fcl, const Record& lazy, const std::string& what) {
  ASSERT_EQ(fcl.u.size(), lazy.u.size()) << what;
  int in_contact = 0;
  for (size_t k = 0; k < fcl.u.size(); ++k) {
    const std::string at = what + ", step " + std::to_string(k);
    const ContactReport &a = fcl.reports[k], &b = lazy.reports[k];
    EXPECT_TRUE(same_bits(fcl.u[k], lazy.u[k])) << at << ": displacements differ";
    EXPECT_TRUE(same_bits(fcl.reaction[k], lazy.reaction[k])) << at << ": reactions differ";
    EXPECT_TRUE(same_bits(a.force, b.force)) << at << ": force " << a.force.transpose() << " vs " << b.force.transpose();
    EXPECT_TRUE(same_bits(a.max_penetration, b.max_penetration)) << at;
    EXPECT_EQ(a.nodes, b.nodes) << at;
    EXPECT_EQ(a.solves, b.solves) << at;
    EXPECT_EQ(a.iterations, b.iterations) << at;
    EXPECT_EQ(a.queries, b.queries) << at;
    EXPECT_EQ(a.converged, b.converged) << at;
    in_contact += a.nodes > 0;
  }
  EXPECT_GT(in_contact, int(fcl.u.size()) / 3) << what << ": the scenario must be in contact most of the time";
}

// A ball of radius R fixed at its bottom.
TissueModel ball(double R, int level) { return scenario::ball_on_base(R, level); }

// Runs `steps` contact steps with tools(k) and records them.
Record run(const TissueModel& m, ContactSettings cs, int steps, const std::function<std::vector<ToolShape>(int)>& tools) {
  ContactSolver contact(m, cs);
  SimState s = make_sim_state(m);
  const StepInput base = make_step_input(m);
  Record r;
  ContactReport rep;
  for (int k = 0; k < steps; ++k) {
    contact.step(m, base, tools(k), s, rep);
    EXPECT_FALSE(s.failed) << s.failure;
    r.add(s, rep);
  }
  return r;
}

ContactSettings with(ContactSettings cs, bool lazy, double slack) {
  cs.lazy_refit = lazy;
  cs.refit_slack = slack;
  return cs;
}

const double kSlacks[] = {0.0, 0.5, 4.0};

// A capsule of radius r pressing 6 mm into the top of a ball in 1 mm steps, then sliding
// 12 mm sideways in 1 mm steps (kinematic: it pushes the tissue ahead; penalty: it slides).
std::vector<ToolShape> sliding_probe(double R, double r, int k) {
  const double depth = 1e-3 * std::min(k, 6), slide = 1e-3 * std::max(0, k - 6);
  const double prev_depth = 1e-3 * std::min(std::max(k - 1, 0), 6), prev_slide = 1e-3 * std::max(0, k - 7);
  const Vec3 tip(slide, 0, R - depth), prev_tip(prev_slide, 0, R - prev_depth);
  return {capsule_shape(tip + Vec3(0, 0, r), tip + Vec3(0, 0, r + 0.1), r, k ? Vec3(tip - prev_tip) : Vec3::Zero())};
}

TEST(ContactRefit, LazyRefitGivesTheSameKinematicContactBitForBit) {
  const double R = 0.05, r = 0.004;
  const TissueModel m = ball(R, 4);
  auto tools = [&](int k) { return sliding_probe(R, r, k); };
  const Record fcl = run(m, with({}, false, 0.5), 19, tools);
  for (double slack : kSlacks) expect_same(fcl, run(m, with({}, true, slack), 19, tools), "slack " + std::to_string(slack));
  // FCL's shape queries (refit every query too) find the same contacts.
  ContactSettings shapes;
  shapes.fcl_shape_queries = true;
  const Record fcl_shapes = run(m, shapes, 19, tools);
  for (size_t k = 0; k < fcl.u.size(); ++k) EXPECT_LE((fcl.u[k] - fcl_shapes.u[k]).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ContactRefit, BorrowedInputGivesTheSameStepsAndIsPutBack) {
  // ContactSolver::step with a non-const input sets the held rows in it for each solve and
  // puts them back, instead of copying it: the same steps bit for bit, the input unchanged.
  // The scene prescribes z on a patch under the sliding probe (nodes the probe may hold on
  // all axes) and all axes on a few nodes beside it (driven: no contact).
  const double R = 0.05, r = 0.004;
  const TissueModel m = ball(R, 4);
  StepInput base = make_step_input(m);
  int partial = 0, driven = 0;
  for (int i = 0; i < m.n; ++i) {
    const Vec3 X = m.rest.positions.row(i).transpose();
    if (X.z() < 0.8 * R) continue;
    if (std::abs(X.y()) < 0.004 && X.x() > 0.004 && X.x() < 0.01) {
      base.prescribed(i, 2) = 1;
      base.prescribed_u(i, 2) = -0.001;
      ++partial;
    } else if (std::abs(X.y()) > 0.012 && std::abs(X.y()) < 0.016 && std::abs(X.x()) < 0.004) {
      base.prescribed.row(i).setOnes();
      base.prescribed_u.row(i) = Eigen::RowVector3d(0, 0, -0.0005);
      ++driven;
    }
  }
  ASSERT_GT(partial, 0);
  ASSERT_GT(driven, 0);
  const StepInput original = base;
  ContactSolver copying(m), borrowing(m);
  SimState s_copy = make_sim_state(m), s_borrow = make_sim_state(m);
  Record copied, borrowed;
  ContactReport rep;
  for (int k = 0; k < 19; ++k) {
    const std::vector<ToolShape> tools = sliding_probe(R, r, k);
    copying.step(m, static_cast<const StepInput&>(base), tools, s_copy, rep);
    copied.add(s_copy, rep);
    borrowing.step(m, base, tools, s_borrow, rep);
    borrowed.add(s_borrow, rep);
    ASSERT_FALSE(s_borrow.failed) << s_borrow.failure;
    EXPECT_TRUE(std::memcmp(base.prescribed.data(), original.prescribed.data(), size_t(base.prescribed.size())) == 0) << k;
    EXPECT_TRUE(same_bits(base.prescribed_u, original.prescribed_u)) << k;
    EXPECT_TRUE(same_bits(base.force, original.force)) << k;
  }
  expect_same(copied, borrowed, "borrowed input");
}

TEST(ContactRefit, LazyRefitGivesTheSamePenaltyContactBitForBit) {
  const double R = 0.05, r = 0.006;
  const TissueModel m = ball(R, 3);
  ContactSettings penalty;
  penalty.method = ContactSettings::Method::penalty;
  penalty.penalty_stiffness = 1e8;
  auto tools = [&](int k) { return sliding_probe(R, r, k); };
  const Record fcl = run(m, with(penalty, false, 0.5), 19, tools);
  for (double slack : kSlacks)
    expect_same(fcl, run(m, with(penalty, true, slack), 19, tools), "penalty, slack " + std::to_string(slack));
}

// Grasper jaws (two boxes) and shaft (a capsule) pointing down into the top of a ball,
// pressing 4 mm, then opening there (the jaws turn in the tissue) and closing again.
std::vector<ToolShape> grasper(double R, int k) {
  tools::InstrumentDef g;
  g.type = tools::InstrumentDef::Type::grasper;
  g.radius = 0.004;
  g.jaw_length = 0.015;
  auto pose = [&](int j) {
    tools::InstrumentPose p;
    p.axis = Vec3(0, 0, -1);
    p.tip = Vec3(0.002, 0.001, R + 0.003 - 1e-3 * std::min(std::max(j, 0), 7));
    p.jaw_closed = false;
    const int phase = std::max(0, j - 7);  // 0 .. 6 opening, then closing
    p.jaw_opening = phase <= 6 ? phase / 6.0 : std::max(0.0, 1.0 - (phase - 6) / 6.0);
    return p;
  };
  const tools::InstrumentPose now = pose(k), before = pose(k - 1);
  return {tools::jaw_shape(g, now, before, +1), tools::jaw_shape(g, now, before, -1), tools::shaft_shape(g, now, before)};
}

TEST(ContactRefit, LazyRefitGivesTheSameGrasperJawContactBitForBit) {
  const double R = 0.05;
  const TissueModel m = ball(R, 4);
  auto tools = [&](int k) { return grasper(R, k); };
  const Record fcl = run(m, with({}, false, 0.5), 20, tools);
  for (double slack : kSlacks)
    expect_same(fcl, run(m, with({}, true, slack), 20, tools), "jaws, slack " + std::to_string(slack));
  // Penalty contact with three tools: the triangles' order matters to the force sums.
  ContactSettings penalty;
  penalty.method = ContactSettings::Method::penalty;
  const TissueModel small = ball(R, 3);
  const Record fcl_penalty = run(small, with(penalty, false, 0.5), 20, tools);
  for (double slack : kSlacks)
    expect_same(fcl_penalty, run(small, with(penalty, true, slack), 20, tools), "jaws, penalty, slack " + std::to_string(slack));
}

TEST(ContactRefit, LazyRefitGivesTheSameBenchProbeOnTheLiverBitForBit) {
  // The bench's liver_probe case on the 2.5k liver: an 8 mm probe pressed 15 mm, held, withdrawn.
  Record rec[2];
  for (int mode = 0; mode < 2; ++mode) {
    vdmsim::PreparedScene ps = vdmsim::bench_probe_scene("liver_L4.obj", 60, false);
    ps.scene.contact.lazy_refit = mode == 1;
    vdmsim::SceneSimulation sim(ps);
    for (int f = 0; f < 60; ++f) {
      sim.advance(f);
      ASSERT_FALSE(sim.state().failed) << sim.state().failure;
      rec[mode].add(sim.state(), sim.contact_report());
    }
  }
  expect_same(rec[0], rec[1], "liver probe");
}

}  // namespace
}  // namespace vdm
