#include "app/studies/ladder_cases.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "app/studies/model_compare.hpp"
#include "app/studies/paper_beam.hpp"
#include "app/studies/surface_samples.hpp"
#include "engine/elastic_moduli.hpp"
#include "engine/fem/tet_mesh.hpp"

namespace vdmsim {

const double kLadderPunchDistances[kLadderPunchRadii] = {1.5, 2, 3, 4};

namespace {

constexpr double kPunchDepth = 0.001;  // m: deeper, the bonded rim turns the finest FEM's tets over
constexpr int kPunchSteps = 4, kBeamSteps = 5;

struct CaseSetup {
  vdm::fem::TetMesh tets;  // the FEM's mesh (its surface is the surface models')
  LoadCase load;
  vdm::NodeMat points;     // the measure points (rest positions)
};

CaseSetup punch_setup(int level) {
  CaseSetup s;
  const BoxWithDisk spec = punch_level(level);
  std::string error;
  if (!mesh_box_with_disk(spec, s.tets, error)) throw std::runtime_error("the punch's block: " + error);
  const vdm::SurfaceMesh& surface = s.tets.surface;
  const int n = surface.node_count();
  const double top = spec.size.z() / 2, tol = 1e-9;
  LoadCase& lc = s.load;
  lc.name = "punch";
  lc.fixed = vdm::FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i) {
    const auto x = surface.positions.row(i);
    if (x(2) < -top + tol) lc.fixed.row(i).setOnes();
    if (x(2) > top - tol && std::hypot(x(0), x(1)) <= spec.disk_radius + tol) lc.moved.push_back(i);
    lc.tracked.push_back(i);
  }
  for (int k = 1; k <= kPunchSteps; ++k) {
    vdm::NodeMat t = vdm::NodeMat::Zero(static_cast<Eigen::Index>(lc.moved.size()), 3);
    t.col(2).setConstant(-kPunchDepth * k / kPunchSteps);
    lc.targets.push_back(t);
  }
  s.points.resize(kLadderPunchRadii * kLadderPunchAzimuths, 3);
  for (int r = 0; r < kLadderPunchRadii; ++r)
    for (int a = 0; a < kLadderPunchAzimuths; ++a) {
      const double rho = kLadderPunchDistances[r] * kLadderPunchRadius;
      const double phi = 2 * 3.14159265358979323846 * (a + 0.5) / kLadderPunchAzimuths;
      s.points.row(r * kLadderPunchAzimuths + a) = vdm::Vec3(rho * std::cos(phi), rho * std::sin(phi), top).transpose();
    }
  return s;
}

BeamCase beam_case(const std::string& name) {
  if (name == "stretch") return BeamCase::stretch;
  if (name == "bend") return BeamCase::bend;
  if (name == "twist") return BeamCase::twist;
  throw std::runtime_error("not a beam case: " + name);
}

CaseSetup beam_setup(const std::string& which, int cells_across) {
  BeamConfig b;
  b.cells_across = cells_across;
  b.cells_along = 5 * cells_across;
  b.steps = kBeamSteps;
  b.stretch = 0.2;
  b.bend = 0.2;  // the end moved by one width
  b.twist_deg = 30;
  CaseSetup s;
  s.tets = vdm::fem::make_box_tets(vdm::Vec3(b.width, b.length, b.width), b.cells_across, b.cells_along, b.cells_across,
                                   vdm::Vec3(0, b.length / 2, 0));
  s.load = beam_load_case(b, beam_case(which));
  s.load.tracked.clear();
  for (int i = 0; i < s.tets.surface.node_count(); ++i) s.load.tracked.push_back(i);
  s.points.resize(3, 3);
  for (int k = 0; k < 3; ++k) s.points.row(k) = vdm::Vec3(0, 0.25 * (k + 1) * b.length, b.width / 2).transpose();
  return s;
}

}  // namespace

BoxWithDisk punch_level(int level) {
  // The rim's tet size, its growth with the distance from the rim, the largest size.
  static const double levels[3][3] = {{0.5e-3, 0.4, 0.012}, {0.35e-3, 0.3, 0.010}, {0.25e-3, 0.2, 0.007}};
  const int l = std::max(0, std::min(2, level));
  BoxWithDisk spec;
  spec.disk_radius = kLadderPunchRadius;
  spec.h_min = levels[l][0];
  spec.grade = levels[l][1];
  spec.h_max = levels[l][2];
  return spec;
}

Trajectory run_ladder_case(const LadderConfig& c) {
  const bool punch = c.scenario == "punch";
  if (!punch && c.scenario != "beams") throw std::runtime_error("not a load case: " + c.scenario);
  const CaseSetup s = punch ? punch_setup(c.mesh) : beam_setup(c.test_case, c.mesh);
  const vdm::SurfaceMesh& surface = s.tets.surface;
  const double young = kLadderCaseYoung;
  CaseResult r;
  switch (c.model) {
    case LadderModel::fem:
      r = run_fem_case(s.tets, young, kLadderPoisson, s.load);
      break;
    case LadderModel::vdm_paper:
    case LadderModel::vdm_membrane: {
      const vdm::VdmModuli m = vdm::vdm_moduli_from_elastic(young, kLadderPoisson);
      VdmParams p;
      p.bulk = m.bulk;
      p.connectivity = m.connectivity;
      p.capsule = c.model == LadderModel::vdm_paper ? vdm::CapsuleForm::paper : vdm::CapsuleForm::membrane;
      r = run_vdm_case(surface, p, s.load);
      break;
    }
    case LadderModel::vdm_core:
      r = run_core_case(surface, young, c.cell_size, s.load);
      break;
  }
  const SurfaceSamples samples(surface, s.points);
  Trajectory tr;
  tr.nodes = c.model == LadderModel::fem ? s.tets.node_count() : surface.node_count();
  if (!r.converged) tr.unconverged = 1;
  vdm::NodeMat at;
  // Frame k is step k (the rest, index 0 of the case's result, left out).
  for (size_t k = 1; k < r.u.size(); ++k) {
    samples.interpolate(r.u[k], at);
    tr.u.push_back(at);
    // The punch's force from the work of its face: the face moves down by the depth so far.
    const double depth = kPunchDepth * double(k) / kPunchSteps;
    tr.force.push_back(punch ? vdm::Vec3(0, 0, r.work[k] / depth) : vdm::Vec3::Zero());
    tr.step_ms.push_back(r.step_ms[k]);
    tr.volume_rel.push_back(r.volume_rel[k]);
  }
  return tr;
}

}  // namespace vdmsim
