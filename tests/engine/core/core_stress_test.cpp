// The elastic core's stress (engine/core/core_stress.hpp) against elasticity: a bar under
// uniaxial strain takes E eps along its axis and nothing across it (Poisson's ratio 0); a bar
// pulled by its ends, its sides free, carries its end force through its section with the
// fluid's pressure as the volumetric part (an incompressible solid of modulus 3 mu = 1.5 E);
// a rigid rotation is stress-free; an organ under a uniform outer pressure is under that
// pressure on every axis. Then the stress view: its top 1 % lies under a probe pressed into a
// liver, on the project's liver, on an irregular one and on SOFA's scanned liver (when
// ../shared/assets is there); and contact pressure over the nodes' areas adds up to the contact
// force.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "app/mesh_prep/prepare_mesh.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "engine/contact.hpp"
#include "engine/core/core_stress.hpp"
#include "engine/core/elastic_core.hpp"
#include "engine/geometry.hpp"
#include "engine/mesh_topology.hpp"
#include "engine/organ_solver.hpp"
#include "engine/shapes.hpp"
#include "engine/tool_shape.hpp"
#include "render/render_scene.hpp"
#include "support/free_input.hpp"
#include "support/irregular_liver.hpp"
#include "support/scratch_dir.hpp"

namespace vdm::core {
namespace {

namespace fs = std::filesystem;

constexpr double kStressYoung = 3000;

CoreModel stress_core(const SurfaceMesh& s, double h, const FlagMat& fixed = FlagMat(), int max_held = 300) {
  CoreDef def;
  def.surface = s;
  def.young_modulus = kStressYoung;
  def.cell_size = h;
  def.fixed = fixed;
  def.settings.max_held = max_held;
  CoreModel m;
  std::string error;
  EXPECT_TRUE(build_core_model(def, m, error)) << error;
  return m;
}

// The tets whose cube is wholly inside and whose centre lies within the box [lo, hi].
std::vector<size_t> tets_within(const CoreModel& m, const Vec3& lo, const Vec3& hi) {
  std::vector<size_t> out;
  for (Eigen::Index q = 0; q < m.cubes.rows(); ++q) {
    if (m.fill[q] < 1) continue;
    const Vec3 centre = m.lattice.row(m.cubes(q, 0)).transpose() + Vec3::Constant(m.h / 2);
    if ((centre.array() < lo.array()).any() || (centre.array() > hi.array()).any()) continue;
    for (int t = 0; t < 6; ++t) out.push_back(static_cast<size_t>(6 * q + t));
  }
  return out;
}

// A 12 x 3 x 3 cm bar along x, centred at the origin, cells of 5 mm.
const Vec3 kBar(0.12, 0.03, 0.03);
SurfaceMesh bar() { return make_box(kBar, 24, 6, 6); }

TEST(CoreStress, UniaxialStrainTakesYoungsModulusAlongTheAxisAndNothingAcross) {
  // Every surface node on u = (eps x, 0, 0), held by the factor (no free entry: no volume row,
  // no pressure). With Poisson's ratio 0 uniaxial strain is also uniaxial stress: the interior
  // takes sigma_xx = E eps and nothing on the other components. (The ties are springs in
  // series with the core, but every node along the sides pins the lattice's x motion where it
  // is: the interior stays on the imposed strain.)
  const SurfaceMesh s = bar();
  const CoreModel m = stress_core(s, 0.005, FlagMat(), 0);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  const double eps = 0.01;
  for (int i = 0; i < m.ns; ++i) {
    in.prescribed.row(i).setOnes();
    in.prescribed_u(i, 0) = eps * s.positions(i, 0);
  }
  step(m, in, st);
  ASSERT_TRUE(st.stats.converged);
  EXPECT_EQ(st.pressure, 0.0);
  CoreStrain c;
  core_strain(m, st, c);
  const std::vector<size_t> inner = tets_within(m, Vec3(-0.03, -0.01, -0.01), Vec3(0.03, 0.01, 0.01));
  ASSERT_GE(inner.size(), 60u);
  double worst_axial = 0, worst_other = 0;
  for (const size_t t : inner) {
    const Eigen::Matrix3d sigma = kStressYoung * c.tet[t];
    worst_axial = std::max(worst_axial, std::abs(sigma(0, 0) / (kStressYoung * eps) - 1));
    Eigen::Matrix3d other = sigma;
    other(0, 0) = 0;
    worst_other = std::max(worst_other, other.cwiseAbs().maxCoeff() / (kStressYoung * eps));
  }
  // The surface's per-axis stress in the bar's middle third, as the stress view shows it.
  NodeMat stress(m.ns, 3), strain(m.ns, 3);
  surface_stress(m, c, st.pressure, stress, strain);
  double worst_surface = 0;
  for (int i = 0; i < m.ns; ++i)
    if (std::abs(s.positions(i, 0)) < 0.02) worst_surface = std::max(worst_surface, std::abs(stress(i, 0) / (kStressYoung * eps) - 1));
  std::printf("uniaxial strain: interior sigma_xx within %.2g %% of E eps, other components below %.2g %% of it; "
              "surface (middle third) sigma_xx within %.2g %%\n",
              100 * worst_axial, 100 * worst_other, 100 * worst_surface);
  EXPECT_LT(worst_axial, 0.02);
  EXPECT_LT(worst_other, 0.02);
  EXPECT_LT(worst_surface, 0.03);
}

TEST(CoreStress, BarPulledByItsEndsCarriesTheForceWithTheFluidsPressure) {
  // The bar's end faces held, one pulled 1 % along x, its sides free. The fluid keeps the
  // volume: the sides come in and the pressure drops. Equilibrium: the interior's axial stress
  // (core and fluid) is the end's force over the section, the sides' stresses vanish (free
  // faces), and then -p = -E eps_lateral, so sigma_xx = E (eps_xx - eps_lateral): with the
  // lateral strain -eps_xx / 2 of an incompressible bar, 1.5 E eps_xx (3 mu, mu = E/2).
  const SurfaceMesh s = bar();
  const double half = kBar.x() / 2, pull = 0.01 * kBar.x();
  FlagMat fixed = FlagMat::Zero(s.node_count(), 3);
  for (int i = 0; i < s.node_count(); ++i)
    if (s.positions(i, 0) < -half + 1e-9) fixed.row(i).setOnes();
  const CoreModel m = stress_core(s, 0.005, fixed);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  for (int i = 0; i < m.ns; ++i)
    if (s.positions(i, 0) > half - 1e-9) {
      in.prescribed.row(i).setOnes();
      in.prescribed_u(i, 0) = pull;
    }
  step(m, in, st);
  ASSERT_TRUE(st.stats.converged);
  EXPECT_LT(std::abs(st.volume_rel_error), 1e-9);
  double force = 0;
  for (int i = 0; i < m.ns; ++i)
    if (s.positions(i, 0) > half - 1e-9) force += st.reaction(i, 0);
  const double section = kBar.y() * kBar.z(), traction = force / section;
  CoreStrain c;
  core_strain(m, st, c);
  // The middle third's cubes that are wholly inside: the section's inner 2 x 2 cm.
  const std::vector<size_t> inner = tets_within(m, Vec3(-0.02, -0.01, -0.01), Vec3(0.02, 0.01, 0.01));
  ASSERT_GE(inner.size(), 60u);
  Eigen::Matrix3d mean_eps = Eigen::Matrix3d::Zero();
  for (const size_t t : inner) mean_eps += c.tet[t] / static_cast<double>(inner.size());
  Eigen::Matrix3d sigma = kStressYoung * mean_eps;
  sigma.diagonal().array() -= st.pressure;
  const double lateral = std::max(std::abs(sigma(1, 1)), std::abs(sigma(2, 2)));
  const double modulus = sigma(0, 0) / mean_eps(0, 0);
  std::printf("pulled bar: end force / section %.2f Pa, interior sigma_xx %.2f Pa (%+.2f %%); sides %.3f Pa "
              "(%.2f %% of it); pressure %.2f Pa, E eps_yy %.2f Pa; sigma_xx / eps_xx = %.4f E\n",
              traction, sigma(0, 0), 100 * (sigma(0, 0) / traction - 1), lateral, 100 * lateral / sigma(0, 0),
              st.pressure, kStressYoung * mean_eps(1, 1), modulus / kStressYoung);
  EXPECT_LT(st.pressure, 0.0);  // the fluid pulls the sides in
  EXPECT_NEAR(sigma(0, 0) / traction, 1.0, 0.03);
  EXPECT_LT(lateral, 0.03 * sigma(0, 0));
  EXPECT_NEAR(modulus / kStressYoung, 1.5, 0.05);
}

TEST(CoreStress, RigidRotationIsStressFree) {
  // Every surface node on a large rigid rotation and translation: no tet is strained beyond
  // what the step's tolerance leaves (the lattice to tolerance x size, over a cell).
  const SurfaceMesh s = make_box(Vec3(0.06, 0.03, 0.02), 6, 3, 2);
  const CoreModel m = stress_core(s, 0.007);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.8, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(0.01, -0.02, 0.005);
  for (int i = 0; i < m.ns; ++i) {
    const Vec3 X = s.positions.row(i);
    in.prescribed.row(i).setOnes();
    in.prescribed_u.row(i) = (R * X + t - X).transpose();
  }
  step(m, in, st);
  ASSERT_TRUE(st.stats.converged);
  CoreStrain c;
  core_strain(m, st, c);
  double worst = 0;
  for (const Eigen::Matrix3d& e : c.tet) worst = std::max(worst, e.cwiseAbs().maxCoeff());
  NodeMat stress(m.ns, 3), strain(m.ns, 3);
  surface_stress(m, c, st.pressure, stress, strain);
  std::printf("rigid rotation of 0.8 rad: largest tet strain %.2g, surface stress %.2g Pa\n", worst,
              stress.cwiseAbs().maxCoeff());
  const double floor = 2 * m.settings.tolerance * m.size / m.h;
  EXPECT_LT(worst, floor);
  EXPECT_LT(stress.cwiseAbs().maxCoeff(), floor * kStressYoung);
}

TEST(CoreStress, UniformOuterPressureIsTheStressOnEveryAxis) {
  // A ball on its held base under a uniform outer pressure P: the fluid takes it all (p = P),
  // the core does not deform, and the stress is -P on every axis, with no shear.
  const SurfaceMesh s = make_icosphere(0.04, 4);
  FlagMat fixed = FlagMat::Zero(s.node_count(), 3);
  for (int i = 0; i < s.node_count(); ++i)
    if (s.positions(i, 2) < -0.035) fixed.row(i).setOnes();
  const CoreModel m = stress_core(s, 0.008, fixed);
  CoreState st = make_core_state(m);
  StepInput in = test::free_input(m.ns);
  const double P = 200;
  in.pressure = Vec::Constant(m.ns, P);
  step(m, in, st);
  ASSERT_TRUE(st.stats.converged);
  CoreStrain c;
  NodeMat stress(m.ns, 3), strain(m.ns, 3);
  core_surface_stress(m, st, c, stress, strain);
  double mises = 0;
  for (const Eigen::Matrix3d& e : c.tet) mises = std::max(mises, von_mises(kStressYoung * e));
  std::printf("outer pressure %.0f Pa: fluid %.6f Pa; surface stress from %.6f to %.6f Pa; von Mises below %.2g Pa\n",
              P, st.pressure, stress.minCoeff(), stress.maxCoeff(), mises);
  EXPECT_NEAR(st.pressure, P, 1e-6 * P);
  EXPECT_LT((stress.array() + P).abs().maxCoeff(), 1e-6 * P);
  EXPECT_LT(strain.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(mises, 1e-6 * P);
}

TEST(CoreStress, VonMisesOfUniaxialAndShearStress) {
  // sigma_vm = |sigma| for uniaxial stress, sqrt(3) |tau| for pure shear, 0 for a pressure.
  Eigen::Matrix3d uni = Eigen::Matrix3d::Zero(), shear = Eigen::Matrix3d::Zero();
  uni(0, 0) = 5;
  shear(0, 1) = shear(1, 0) = 2;
  EXPECT_NEAR(von_mises(uni), 5, 1e-12);
  EXPECT_NEAR(von_mises(shear), 2 * std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(von_mises(-7 * Eigen::Matrix3d::Identity()), 0, 1e-12);
}

// --- The stress view of a pressed organ -----------------------------------------------------

struct Pressed {
  SimState state;
  ContactReport report;
};

// A 4 mm probe pressed `depth` into the organ `mesh` at `touch` (straight down) in 20 steps,
// on the core (cells of 1 cm, E 3 kPa) with the stress computed; the underside below z_fixed
// held; `method` the contact's.
Pressed press_organ(const SurfaceMesh& mesh, const Vec3& touch, double depth, double z_fixed,
                    ContactSettings::Method method) {
  Pressed out;
  TissueDef def = default_tissue(mesh);
  def.fixed = FlagMat::Zero(def.mesh.node_count(), 3);
  for (int i = 0; i < def.mesh.node_count(); ++i)
    if (def.mesh.positions(i, 2) < z_fixed) def.fixed.row(i).setOnes();
  TissueModel m;
  std::string error;
  EXPECT_TRUE(build_tissue_model(def, m, error)) << error;
  CoreDef cd;
  cd.surface = m.rest;
  cd.young_modulus = kStressYoung;
  cd.cell_size = 0.01;
  cd.fixed = m.held;
  cd.compute_stress = true;
  CoreModel cm;
  EXPECT_TRUE(build_core_model(cd, cm, error)) << error;
  const std::unique_ptr<OrganSolver> solver = make_core_solver(std::move(cm), 0.05);
  out.state = make_sim_state(m);
  ContactSettings cs;
  cs.method = method;
  cs.friction = 0;
  ContactSolver contact(m, cs);
  contact.set_solver(solver.get());
  const StepInput base = make_step_input(m);
  const Vec3 up(0, 0, 1);
  const double r = 0.004;
  const int steps = 20;
  for (int k = 0; k <= steps; ++k) {
    const Vec3 tip = touch + (0.002 - (depth + 0.002) * k / steps) * up;
    contact.step(m, base, {capsule_shape(tip + r * up, tip + 0.2 * up, r, k ? Vec3(-(depth + 0.002) / steps * up) : Vec3::Zero())},
                 out.state, out.report);
    EXPECT_FALSE(out.state.failed) << out.state.failure;
    if (out.state.failed) break;
  }
  return out;
}

// The share of the top 1 % of the stress view's default quantity (magnitude) within `radius`
// of `point`.
double top_share_near(const SimState& s, const Vec3& point, double radius) {
  std::vector<float> q;
  render::scalar_field(render::Quantity::stress_magnitude, s, q);
  std::vector<int> order(q.size());
  for (size_t i = 0; i < q.size(); ++i) order[i] = static_cast<int>(i);
  const size_t top = std::max<size_t>(1, order.size() / 100);
  std::partial_sort(order.begin(), order.begin() + long(top), order.end(),
                    [&](int a, int b) { return q[size_t(a)] > q[size_t(b)]; });
  size_t near = 0;
  for (size_t k = 0; k < top; ++k) near += (s.x.row(order[k]).transpose() - point).norm() <= radius;
  return double(near) / double(top);
}

void expect_stress_under_the_probe(const char* what, const SurfaceMesh& mesh, const Vec3& touch = Vec3(0.035, 0.0, 0.0603),
                                   double z_fixed = -0.03) {
  const Pressed p = press_organ(mesh, touch, 0.010, z_fixed, ContactSettings::Method::kinematic);
  const double share = top_share_near(p.state, touch, 0.03);
  std::printf("%s on the core: contact force %.3f N, %d nodes; largest stress magnitude %.0f Pa; top 1 %% of it within "
              "3 cm of the probe: %.0f %%\n",
              what, p.report.force.norm(), p.report.nodes, p.state.stress.rowwise().norm().maxCoeff(), 100 * share);
  EXPECT_GT(p.report.nodes, 0);
  EXPECT_TRUE(p.state.stress.allFinite());
  EXPECT_EQ(share, 1.0);
}

TEST(CoreStress, StressViewFindsTheProbeOnTheLiver) {
  expect_stress_under_the_probe("the 10k liver", vdmsim::make_liver_mesh(5));
}

TEST(CoreStress, StressViewFindsTheProbeOnAnIrregularSurface) {
  // The liver jittered and edge-flipped as a CT surface is (tests/support/irregular_liver.hpp).
  SurfaceMesh mesh = test::irregular_liver(5, 11);
  const MeshCheck check = check_and_orient_surface(mesh);
  ASSERT_TRUE(check.ok()) << check.message;
  expect_stress_under_the_probe("the irregular 10k liver", mesh);
}

TEST(CoreStress, StressViewFindsTheProbeOnTheSharedScannedLiver) {
  // SOFA's scanned liver (../shared/assets, third-party: used in place, never copied), made an
  // organ by prepare-mesh at an adult's size (22 cm, 10k nodes): pressed on top near its middle,
  // its lowest 30 % held.
  const fs::path in = fs::path(VDMSIM_SHARED_ASSETS) / "organs/liver-smooth.obj";
  if (!fs::exists(in)) GTEST_SKIP() << "shared assets absent (" << in << "): skipping";
  vdmsim::PrepareMeshOptions opt;
  opt.in = in.string();
  opt.out = (vdmsim::test::scratch_dir("core_stress") / "liver_smooth.obj").string();
  opt.scale = 0.034;
  opt.nodes = 10000;
  opt.center = true;
  std::ostringstream out, err;
  ASSERT_EQ(vdmsim::cmd_prepare_mesh(opt, out, err), 0) << out.str() << err.str();
  const vdmsim::MeshLoadResult r = vdmsim::load_surface_mesh(opt.out);
  ASSERT_TRUE(r.ok) << r.error;
  const NodeMat& P = r.mesh.positions;
  int top = -1;
  for (int i = 0; i < P.rows(); ++i)
    if (P.row(i).head<2>().norm() < 0.03 && (top < 0 || P(i, 2) > P(top, 2))) top = i;
  ASSERT_GE(top, 0);
  const double low = P.col(2).minCoeff(), high = P.col(2).maxCoeff();
  expect_stress_under_the_probe("SOFA's scanned liver (prepared, 10k)", r.mesh, P.row(top).transpose(),
                                low + 0.3 * (high - low));
}

TEST(CoreStress, ContactPressureOverTheNodesAreasIsTheContactForce) {
  // Constraint contact, frictionless: each contact node's pressure is its force over its area
  // vector's length at the pressed geometry, so the pressure over the nodes' areas adds up to
  // the forces' sizes: at least the force on the probe, and not much more (the forces are
  // normal to the probe's round tip, a little apart from its axis).
  const Vec3 touch(0.035, 0.0, 0.0603);
  const Pressed p = press_organ(vdmsim::make_liver_mesh(4), touch, 0.006, -0.03, ContactSettings::Method::constraint);
  double integral = 0;
  int pressed = 0;
  for (int i = 0; i < p.state.x.rows(); ++i) {
    if (p.state.reaction_pressure[i] == 0 || p.state.x(i, 2) < 0) continue;  // the instrument's, not the base's
    ++pressed;
    integral += p.state.reaction_pressure[i] * p.state.area_vectors.row(i).norm();
    EXPECT_NEAR(p.state.reaction_pressure[i] * p.state.area_vectors.row(i).norm(), p.state.reaction.row(i).norm(),
                1e-9 * p.state.reaction.row(i).norm());
  }
  std::printf("constraint contact on the core: %d nodes, pressure over their areas %.4f N, probe force %.4f N\n", pressed,
              integral, p.report.force.norm());
  EXPECT_GT(pressed, 0);
  EXPECT_GE(integral, p.report.force.norm() * (1 - 1e-9));
  EXPECT_LT(integral, 1.1 * p.report.force.norm());
}

}  // namespace
}  // namespace vdm::core
