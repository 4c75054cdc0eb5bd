// VDM against the project's FEM at the same E and nu (issue 26, "must show"; docs/model.md,
// "against the FEM"): the flat punch's dent profile and force, and the beams stretched, bent
// and twisted. VDM's moduli come from the E, nu rule (engine/elastic_moduli.hpp), not fitted
// to these cases. E = 3 kPa, nu = 0.45 throughout.
//
// What is asserted: the FEM is converged (two resolutions within 5 % in every compared
// quantity), VDM keeps its volume to 1e-9, and the targets that hold (the punch force within
// 30 %, the stretch within 10 % for every capsule form; the corotational capsule alone carries
// the bend and the twist). The targets that are missed (the punch's dent profile, the bend and
// the twist with the default model) are printed, not asserted: docs/model.md gives the numbers
// and the reason. The elastic core (model vdm_core) meets every target: asserted in both tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "app/simulation/tet_mesher.hpp"
#include "app/studies/model_compare.hpp"
#include "app/studies/paper_beam.hpp"
#include "engine/elastic_moduli.hpp"
#include "engine/fem/tet_mesh.hpp"
#include "engine/geometry.hpp"

namespace vdmsim {
namespace {

constexpr double kYoung = 3000, kPoisson = 0.45;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double relative(double a, double ref) { return std::abs(a - ref) / std::abs(ref); }

double largest_volume_error(const CaseResult& r) {
  double v = 0;
  for (const double e : r.volume_rel) v = std::max(v, std::abs(e));
  return v;
}

// VDM's moduli from E and nu by the documented rule; direct solves to a tight tolerance.
VdmParams rule_params(vdm::CapsuleForm capsule) {
  const vdm::VdmModuli mod = vdm::vdm_moduli_from_elastic(kYoung, kPoisson);
  VdmParams p;
  p.bulk = mod.bulk;
  p.connectivity = mod.connectivity;
  p.capsule = capsule;
  p.solver.method = vdm::SolverMethod::direct;
  p.solver.tolerance = 1e-10;
  // The corotational capsule's rotations lag by one iteration (docs/model.md): iterated to
  // convergence here (10 iterations per step left the twist 10-25 % short of it).
  if (capsule == vdm::CapsuleForm::corotational) p.solver.nonlinear_iterations = 50;
  return p;
}

// The bending modulus that gives a slender organ the bending stiffness of its solid section
// (docs/model.md, "Bending"): a skin of modulus D around a round section of radius r bends
// with E I = D 2 pi r = E pi r^4 / 4 when D = E r^3 / 8 = E (V/A)^3 (V/A = r/2 for a long
// round bar; a square one gives 4/3 of it).
double section_bending(const vdm::SurfaceMesh& s) {
  const double v_over_a = vdm::enclosed_volume(s.positions, s.triangles, vdm::Vec3::Zero()) /
                          vdm::surface_area(s.positions, s.triangles);
  return kYoung * v_over_a * v_over_a * v_over_a;
}

// --- The flat punch ----------------------------------------------------------------------

// The flat-punch block of docs/model.md: 10 x 10 x 5 cm, bottom held, a flat punch of radius
// a = 5 mm pressed 1 mm into the top's centre in 4 steps. The punch is bonded: the nodes under
// its face are held on all three axes, in both models, on the FEM mesh's own boundary (the
// punch's rim is a mesh line). The FEM mesh is graded from the rim (gmsh).
struct PunchLevel {
  double h_min, grade, h_max;  // m, 1, m
};
constexpr double kPunchRadius = 0.005, kPunchDepth = 0.001;
constexpr int kPunchSteps = 4;

struct PunchRun {
  std::vector<double> dent;  // u_z (m) at each radius, mean over 8 azimuths
  double force = 0;          // N
  CaseResult result;
  double seconds = 0;
};

struct PunchBlock {
  vdm::fem::TetMesh tets;
  LoadCase load;
};

PunchBlock punch_block(const PunchLevel& level) {
  BoxWithDisk spec;
  spec.disk_radius = kPunchRadius;
  spec.h_min = level.h_min;
  spec.grade = level.grade;
  spec.h_max = level.h_max;
  PunchBlock b;
  std::string error;
  if (!mesh_box_with_disk(spec, b.tets, error)) {
    ADD_FAILURE() << error;
    return b;
  }
  const vdm::SurfaceMesh& s = b.tets.surface;
  const int n = s.node_count();
  const double top = spec.size.z() / 2, tol = 1e-9;
  LoadCase& lc = b.load;
  lc.name = "punch";
  lc.fixed = vdm::FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    const auto X = s.positions.row(i);
    if (X(2) < -top + tol) lc.fixed.row(i).setOnes();
    if (X(2) > top - tol && std::hypot(X(0), X(1)) <= kPunchRadius + tol) lc.moved.push_back(i);
    lc.tracked.push_back(i);
  }
  for (int k = 1; k <= kPunchSteps; ++k) {
    vdm::NodeMat t = vdm::NodeMat::Zero(static_cast<Eigen::Index>(lc.moved.size()), 3);
    t.col(2).setConstant(-kPunchDepth * k / kPunchSteps);
    lc.targets.push_back(t);
  }
  return b;
}

// u_z at rest position (x, y) of the top face, interpolated in the top triangle holding it.
double top_uz(const vdm::SurfaceMesh& s, const vdm::NodeMat& u, double top, double x, double y) {
  const auto& P = s.positions;
  for (int t = 0; t < s.triangle_count(); ++t) {
    const int a = s.triangles(t, 0), b = s.triangles(t, 1), c = s.triangles(t, 2);
    if (std::min({P(a, 2), P(b, 2), P(c, 2)}) < top - 1e-9) continue;
    const double x1 = P(b, 0) - P(a, 0), y1 = P(b, 1) - P(a, 1), x2 = P(c, 0) - P(a, 0), y2 = P(c, 1) - P(a, 1);
    const double det = x1 * y2 - x2 * y1, px = x - P(a, 0), py = y - P(a, 1);
    const double l1 = (px * y2 - x2 * py) / det, l2 = (x1 * py - px * y1) / det, l0 = 1 - l1 - l2;
    if (l0 < -1e-12 || l1 < -1e-12 || l2 < -1e-12) continue;
    return l0 * u(a, 2) + l1 * u(b, 2) + l2 * u(c, 2);
  }
  ADD_FAILURE() << "no top triangle holds (" << x << ", " << y << ")";
  return 0;
}

PunchRun punch_run(const PunchBlock& b, CaseResult r, const std::vector<double>& radii, double seconds) {
  PunchRun out;
  const double top = b.tets.surface.positions.col(2).maxCoeff();
  const int azimuths = 8;
  for (const double rho : radii) {
    double sum = 0;
    for (int k = 0; k < azimuths; ++k) {
      const double phi = 2 * 3.14159265358979323846 * (k + 0.5) / azimuths;
      sum += top_uz(b.tets.surface, r.u.back(), top, rho * std::cos(phi), rho * std::sin(phi));
    }
    out.dent.push_back(sum / azimuths);
  }
  out.force = r.work.back() / kPunchDepth;  // the moved nodes go down by the depth, held on x and y
  out.result = std::move(r);
  out.seconds = seconds;
  return out;
}

void print_punch(const char* what, const PunchBlock& b, const PunchRun& r, const std::vector<double>& radii,
                 const PunchRun* ref = nullptr) {
  std::printf("%-14s %5d surface nodes, %5d nodes, %6d tets: force %.4f N", what, b.tets.surface_nodes,
              b.tets.node_count(), b.tets.tet_count(), r.force);
  if (ref) std::printf(" (%+.0f %%)", 100 * (r.force / ref->force - 1));
  std::printf("; dent");
  for (size_t k = 0; k < radii.size(); ++k) {
    std::printf(" %.1fa %.4f mm", radii[k] / kPunchRadius, 1e3 * r.dent[k]);
    if (ref) std::printf(" (%+.0f %%)", 100 * (r.dent[k] / ref->dent[k] - 1));
  }
  std::printf("; |dV/V| %.1e; %.1f s\n", largest_volume_error(r.result), r.seconds);
}

TEST(AgainstTheFem, FlatPunch) {
  const std::vector<double> radii = {1.5 * kPunchRadius, 2 * kPunchRadius, 3 * kPunchRadius, 4 * kPunchRadius};
  const PunchLevel levels[2] = {{0.35e-3, 0.3, 0.010}, {0.25e-3, 0.2, 0.007}};
  std::vector<PunchBlock> blocks;
  std::vector<PunchRun> fem, vdm;
  for (const PunchLevel& level : levels) {
    blocks.push_back(punch_block(level));
    const PunchBlock& b = blocks.back();
    ASSERT_GT(b.load.moved.size(), 20u);
    auto t0 = std::chrono::steady_clock::now();
    CaseResult r = run_fem_case(b.tets, kYoung, kPoisson, b.load);
    fem.push_back(punch_run(b, std::move(r), radii, seconds_since(t0)));
    t0 = std::chrono::steady_clock::now();
    r = run_vdm_case(b.tets.surface, rule_params(vdm::CapsuleForm::membrane), b.load);
    vdm.push_back(punch_run(b, std::move(r), radii, seconds_since(t0)));
  }
  print_punch("fem coarse", blocks[0], fem[0], radii);
  print_punch("fem fine", blocks[1], fem[1], radii);
  print_punch("vdm coarse", blocks[0], vdm[0], radii, &fem[1]);
  print_punch("vdm fine", blocks[1], vdm[1], radii, &fem[1]);
  {
    // The bending term at the section rule's modulus widens the dent further (a block is no
    // slender section): measured, not asserted.
    VdmParams p = rule_params(vdm::CapsuleForm::membrane);
    p.bending = section_bending(blocks[1].tets.surface);
    const auto t0 = std::chrono::steady_clock::now();
    CaseResult r = run_vdm_case(blocks[1].tets.surface, p, blocks[1].load);
    const PunchRun bent = punch_run(blocks[1], std::move(r), radii, seconds_since(t0));
    print_punch("vdm + bending", blocks[1], bent, radii, &fem[1]);
    EXPECT_LT(largest_volume_error(bent.result), 1e-9);
  }
  // The FEM is converged: its two meshes agree within 5 % in every compared quantity.
  for (const PunchRun& r : fem) EXPECT_TRUE(r.result.converged);
  for (size_t k = 0; k < radii.size(); ++k) EXPECT_LT(relative(fem[0].dent[k], fem[1].dent[k]), 0.05) << radii[k];
  EXPECT_LT(relative(fem[0].force, fem[1].force), 0.05);
  // VDM: the volume exact; the punch force within 30 % of the FEM's (the target).
  for (const PunchRun& r : vdm) EXPECT_LT(largest_volume_error(r.result), 1e-9);
  EXPECT_LT(relative(vdm[1].force, fem[1].force), 0.30);
  // The dent profile's target (35 % at 1.5 to 4 a) is missed: measured, not asserted.

  // The elastic core (model vdm_core; its constants, mu = E/2 and kappa = 4 E/h, were fixed on
  // the beams and checked here, research/elastic-core) meets every punch target, at cells of
  // 5 and 2.5 mm, and converges with the cell size (within 10 %).
  std::vector<PunchRun> core;
  for (const double h : {0.005, 0.0025}) {
    const auto t0 = std::chrono::steady_clock::now();
    CaseResult r = run_core_case(blocks[1].tets.surface, kYoung, h, blocks[1].load);
    core.push_back(punch_run(blocks[1], std::move(r), radii, seconds_since(t0)));
    print_punch(h > 0.004 ? "core h 5 mm" : "core h 2.5 mm", blocks[1], core.back(), radii, &fem[1]);
    const PunchRun& c = core.back();
    EXPECT_TRUE(c.result.converged);
    EXPECT_LT(largest_volume_error(c.result), 1e-9);
    EXPECT_LT(relative(c.force, fem[1].force), 0.30) << h;
    for (size_t k = 0; k < radii.size(); ++k) EXPECT_LT(relative(c.dent[k], fem[1].dent[k]), 0.35) << h << ' ' << radii[k];
  }
  EXPECT_LT(relative(core[0].force, core[1].force), 0.10);
  for (size_t k = 0; k < radii.size(); ++k) EXPECT_LT(relative(core[0].dent[k], core[1].dent[k]), 0.10) << radii[k];
}

// --- The beams ---------------------------------------------------------------------------

// A 2 x 10 x 2 cm beam along y (1 x 5 x 1), the end y = 0 clamped, the other end's face moved
// on all three axes: stretched 20 %, bent sideways by one width (2 cm), twisted 30 deg about
// the beam's axis (paper_beam's cases). |u| compared at the final step at A, B, C: the top
// face's centre line at L/4, L/2, 3L/4. The VDM surface is the FEM mesh's boundary.
BeamConfig beam_config(int cells_across, int steps) {
  BeamConfig c;
  c.cells_across = cells_across;
  c.cells_along = 5 * cells_across;
  c.steps = steps;
  c.stretch = 0.2;
  c.bend = 0.2;  // end displacement / length: one width
  c.twist_deg = 30;
  c.young = kYoung;
  c.poisson = kPoisson;
  c.calibrate = false;
  c.fem = vdm::fem::FemSettings{};  // the project's FEM as it ships: nodal volumetric averaging
  return c;
}

vdm::fem::TetMesh beam_tets(const BeamConfig& c) {
  return vdm::fem::make_box_tets(vdm::Vec3(c.width, c.length, c.width), c.cells_across, c.cells_along, c.cells_across,
                                 vdm::Vec3(0, c.length / 2, 0));
}

// max over A, B, C of | |u_a| - |u_ref| | / |u_ref| at the final step; with `each`, the signed
// differences per point.
double worst_point(const CaseResult& a, const CaseResult& ref, std::vector<double>* each = nullptr) {
  double worst = 0;
  for (Eigen::Index p = 0; p < ref.u.back().rows(); ++p) {
    const double ua = a.u.back().row(p).norm(), ur = ref.u.back().row(p).norm();
    worst = std::max(worst, std::abs(ua - ur) / ur);
    if (each) each->push_back(ua / ur - 1);
  }
  return worst;
}

void print_beam(const std::string& what, const CaseResult& r, const CaseResult* ref, double seconds) {
  std::printf("  %-26s |u| A B C = %7.3f %7.3f %7.3f mm", what.c_str(), 1e3 * r.u.back().row(0).norm(),
              1e3 * r.u.back().row(1).norm(), 1e3 * r.u.back().row(2).norm());
  if (ref) {
    std::vector<double> each;
    worst_point(r, *ref, &each);
    std::printf(" (%+.1f %+.1f %+.1f %%)", 100 * each[0], 100 * each[1], 100 * each[2]);
  }
  std::printf("; |dV/V| %.1e; %.1f s\n", largest_volume_error(r), seconds);
}

TEST(AgainstTheFem, Beams) {
  // FEM on 4 and 6 cells across (5 steps: the corotational FEM's equilibrium does not depend
  // on the path); VDM on the 4-cell mesh's surface, 10 steps.
  const BeamConfig fem_coarse = beam_config(4, 5), fem_fine = beam_config(6, 5), vdm_config = beam_config(4, 10);
  const vdm::fem::TetMesh tets_coarse = beam_tets(fem_coarse), tets_fine = beam_tets(fem_fine);
  const double targets[3] = {0.10, 0.15, 0.30};  // the issue's: stretch, bend, twist
  for (const BeamCase which : {BeamCase::stretch, BeamCase::bend, BeamCase::twist}) {
    std::printf("%s\n", to_string(which));
    auto t0 = std::chrono::steady_clock::now();
    const CaseResult fc = run_fem_case(tets_coarse, kYoung, kPoisson, beam_load_case(fem_coarse, which), fem_coarse.fem);
    print_beam("fem 4 cells across", fc, nullptr, seconds_since(t0));
    t0 = std::chrono::steady_clock::now();
    const CaseResult ff = run_fem_case(tets_fine, kYoung, kPoisson, beam_load_case(fem_fine, which), fem_fine.fem);
    print_beam("fem 6 cells across", ff, nullptr, seconds_since(t0));
    EXPECT_TRUE(fc.converged && ff.converged) << to_string(which);
    // The FEM is converged: within 5 % at A, B and C between the two meshes.
    EXPECT_LT(worst_point(fc, ff), 0.05) << to_string(which);
    const LoadCase lc = beam_load_case(vdm_config, which);
    {
      // The elastic core (model vdm_core), cells of 5 mm (4 across): every beam target.
      t0 = std::chrono::steady_clock::now();
      const CaseResult c = run_core_case(tets_coarse.surface, kYoung, 0.005, lc);
      print_beam("core h 5 mm", c, &ff, seconds_since(t0));
      EXPECT_TRUE(c.converged) << to_string(which);
      EXPECT_LT(largest_volume_error(c), 1e-9) << to_string(which);
      EXPECT_LT(worst_point(c, ff), targets[static_cast<int>(which)]) << to_string(which);
    }
    for (const vdm::CapsuleForm form : {vdm::CapsuleForm::membrane, vdm::CapsuleForm::corotational, vdm::CapsuleForm::paper}) {
      t0 = std::chrono::steady_clock::now();
      const CaseResult v = run_vdm_case(tets_coarse.surface, rule_params(form), lc);
      print_beam(std::string("vdm ") + vdm::to_string(form), v, &ff, seconds_since(t0));
      EXPECT_LT(largest_volume_error(v), 1e-9) << to_string(which) << ' ' << vdm::to_string(form);
      // The stretch's target holds for every capsule form; the bend's and the twist's (15 %,
      // 30 %) are missed with the rule's moduli: measured, not asserted.
      if (which == BeamCase::stretch) {
        EXPECT_LT(worst_point(v, ff), targets[0]) << vdm::to_string(form);
      }
    }
    // The bending term at the section rule's modulus, with the rule's moduli and with the skin
    // alone: measured; asserted where it meets a target (the corotational skin alone's bend,
    // which it brings from 10 % to within 5 %).
    for (const vdm::CapsuleForm form : {vdm::CapsuleForm::membrane, vdm::CapsuleForm::corotational})
      for (const bool alone : {false, true}) {
        VdmParams p = rule_params(form);
        p.bending = section_bending(tets_coarse.surface);
        if (alone) p.bulk = 1e-4 * p.connectivity;
        t0 = std::chrono::steady_clock::now();
        const CaseResult v = run_vdm_case(tets_coarse.surface, p, lc);
        print_beam(std::string("vdm ") + vdm::to_string(form) + " + bending" + (alone ? ", skin alone" : ""), v, &ff,
                   seconds_since(t0));
        EXPECT_LT(largest_volume_error(v), 1e-9) << to_string(which) << ' ' << vdm::to_string(form);
        if (alone && form == vdm::CapsuleForm::corotational && which == BeamCase::bend) {
          EXPECT_LT(worst_point(v, ff), targets[1]);
        }
      }
    // Why the bend and the twist die: the bulk term B (A_i^d)^2 / V_i is a spring from each
    // node to its rest position, so it resists a part of the organ moving rigidly. With the
    // skin alone (B = 1e-4 B_ij) the corotational capsule carries the bend and the twist to
    // within the targets; the membrane's componentwise Laplacian still loses the twist.
    for (const vdm::CapsuleForm form : {vdm::CapsuleForm::membrane, vdm::CapsuleForm::corotational}) {
      VdmParams skin = rule_params(form);
      skin.bulk = 1e-4 * skin.connectivity;
      t0 = std::chrono::steady_clock::now();
      const CaseResult v = run_vdm_case(tets_coarse.surface, skin, lc);
      print_beam(std::string("vdm ") + vdm::to_string(form) + ", skin alone", v, &ff, seconds_since(t0));
      EXPECT_LT(largest_volume_error(v), 1e-9) << to_string(which) << ' ' << vdm::to_string(form);
      if (form == vdm::CapsuleForm::corotational) {
        EXPECT_LT(worst_point(v, ff), targets[static_cast<int>(which)]) << to_string(which);
      }
    }
  }
}

}  // namespace
}  // namespace vdmsim
