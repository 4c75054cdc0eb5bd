// Google Benchmark micro-benchmarks of the hot kernels (issue 6), off by default:
//   cmake -S . -B build-bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DVDMSIM_BENCHMARKS=ON
//   cmake --build build-bench --target vdmsim_micro_benchmarks && build-bench/benchmarks/vdmsim_micro_benchmarks
// Kernels on the project's 10k-node liver (assets/meshes/liver_L5.obj): geometry refresh,
// assembly, a pressed step with each solver, the step's results pass, BVH refit and query
// (inside a contact step and alone), the stress view's scalar field and colour lookup, PNG
// encoding of a 720p frame.
#include <benchmark/benchmark.h>

#include <time.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "app/studies/bench.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/studies/quantile.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/contact.hpp"
#include "engine/geometry.hpp"
#include "engine/volume_along.hpp"
#include "engine/axis_incomplete_cholesky.hpp"
#include "engine/axis_matrices.hpp"
#include "engine/incomplete_cholesky.hpp"
#include "engine/node_ordering.hpp"
#include "engine/simd4.hpp"
#include "engine/sparse_ldlt.hpp"
#include "engine/sim_state.hpp"
#include "engine/step_results.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stiffness.hpp"
#include "engine/stress.hpp"
#include "engine/tissue_model.hpp"
#include "render/colormap.hpp"
#include "render/png_io.hpp"
#include "render/render_scene.hpp"

namespace {

double thread_cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

const vdm::SurfaceMesh& liver() {
  static const vdm::SurfaceMesh mesh = [] {
    vdmsim::MeshLoadOptions opt;
    const auto r = vdmsim::load_surface_mesh(std::string(VDMSIM_SOURCE_DIR) + "/assets/meshes/liver_L5.obj", opt);
    if (!r.ok) std::fprintf(stderr, "%s\n", r.error.c_str());
    return r.mesh;
  }();
  return mesh;
}

vdm::TissueModel model(vdm::SolverMethod method) {
  vdm::TissueDef def = vdm::default_tissue(liver());
  def.solver.method = method;
  def.solver.tolerance = 1e-8;
  const int n = def.mesh.node_count();
  def.fixed = vdm::FlagMat::Zero(n, 3);
  for (int i = 0; i < n; ++i)
    if (def.mesh.positions(i, 2) < -0.03) def.fixed.row(i).setOnes();
  vdm::TissueModel m;
  std::string error;
  vdm::build_tissue_model(def, m, error);
  return m;
}

// A patch on the right lobe pushed down by `depth` (m).
void press(const vdm::TissueModel& m, double depth, vdm::StepInput& in) {
  for (int i = 0; i < m.n; ++i)
    if ((m.rest.positions.row(i) - Eigen::RowVector3d(0.035, 0, 0.06)).norm() < 0.012) {
      in.prescribed(i, 2) = 1;
      in.prescribed_u(i, 2) = -depth;
    }
}

// The step's geometry refresh: area sums and volume in one pass, A_i with |A_i|, V_i.
void BM_GeometryRefresh(benchmark::State& st) {
  const vdm::SurfaceMesh& mesh = liver();
  vdm::NodeMat a(mesh.node_count(), 3);
  vdm::Vec v(mesh.node_count()), norms(mesh.node_count());
  std::vector<double> packed;
  for (auto _ : st) {
    const double volume = vdm::packed_area_sums_and_volume(mesh.positions, mesh.triangles, vdm::Vec3::Zero(), packed);
    const vdm::AreaNormSums sums = vdm::unpack_area_vectors_and_norms(packed, a, norms);
    vdm::distributed_volumes_from_norms(norms, sums, volume, v);
    benchmark::DoNotOptimize(v.data());
  }
}
BENCHMARK(BM_GeometryRefresh)->Unit(benchmark::kMicrosecond);

// One check of the step's volume correction: the volume and its slope along a move, in one
// pass over the triangles (engine/volume_along), against what it replaced: the volume and
// the area vectors in two passes (enclosed_volume, distributed_area_vectors). Arg 0: new, 1: old.
void BM_VolumeCheck(benchmark::State& st) {
  const vdm::SurfaceMesh& mesh = liver();
  const int n = mesh.node_count();
  vdm::NodeMat d(n, 3), a(n, 3);
  for (int i = 0; i < n; ++i) d.row(i) = 1e-3 * mesh.positions.row(i);
  const vdm::FlagMat mask = vdm::FlagMat::Zero(n, 3);
  std::vector<double> packed;
  for (auto _ : st) {
    if (st.range(0) == 0) {
      const vdm::VolumeAlong v = vdm::volume_along(mesh.positions, d, &mask, mesh.triangles, vdm::Vec3::Zero(), packed);
      benchmark::DoNotOptimize(v.slope);
    } else {
      const double v = vdm::enclosed_volume(mesh.positions, mesh.triangles, vdm::Vec3::Zero());
      vdm::distributed_area_vectors(mesh.positions, mesh.triangles, a);
      benchmark::DoNotOptimize(v);
      benchmark::DoNotOptimize(a.data());
    }
  }
}
BENCHMARK(BM_VolumeCheck)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The step's assembly of K^x, K^y, K^z (edge weights and three diagonals).
void BM_Assembly(benchmark::State& st) {
  const vdm::TissueModel m = model(vdm::SolverMethod::structured);
  vdm::NodeMat a(m.n, 3);
  vdm::Vec v(m.n), norms(m.n), scratch(m.n);
  vdm::distributed_area_vectors(m.rest.positions, m.rest.triangles, a);
  const vdm::VolumeScale how =
      vdm::distributed_volumes(a, vdm::enclosed_volume(m.rest.positions, m.rest.triangles, vdm::Vec3::Zero()), v);
  for (int i = 0; i < m.n; ++i) norms[i] = a.row(i).norm();
  vdm::AxisStiffness K{vdm::Vec(vdm::Vec::Index(m.edges.size())), vdm::NodeMat(m.n, 3)};
  const vdm::Vec none;
  for (auto _ : st) {
    vdm::assemble_stiffness(m, a, norms, v, how, none, K, scratch);
    benchmark::DoNotOptimize(K.weight.data());
  }
}
BENCHMARK(BM_Assembly)->Unit(benchmark::kMicrosecond);

// One step pressing 1 mm further each time (refresh every step), per solver.
void BM_PressedStep(benchmark::State& st) {
  const auto method = static_cast<vdm::SolverMethod>(st.range(0));
  const vdm::TissueModel m = model(method);
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::StepInput in = vdm::make_step_input(m);
  double depth = 0;
  for (auto _ : st) {
    depth = depth >= 0.015 ? 0.001 : depth + 0.001;
    in.prescribed.setZero();
    press(m, depth, in);
    vdm::step(m, in, s);
    benchmark::DoNotOptimize(s.u.data());
  }
  st.SetLabel(vdm::to_string(method));
}
BENCHMARK(BM_PressedStep)
    ->Arg(static_cast<int>(vdm::SolverMethod::structured))
    ->Arg(static_cast<int>(vdm::SolverMethod::direct))
    ->Arg(static_cast<int>(vdm::SolverMethod::reference))
    ->Unit(benchmark::kMillisecond);

// The end of a step on the 10k liver pressed 5 mm: (0) the results pass (K u, reactions,
// residual sums, contact pressure, strain and stress in one gather over the neighbour
// lists), (1) the two kernels it replaced, the product over the edge list and the strain and
// stress gather (without the residual loop between them), (2) the results pass without stress.
void BM_StepResults(benchmark::State& st) {
  vdm::TissueModel m = model(vdm::SolverMethod::structured);
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::StepInput in = vdm::make_step_input(m);
  for (int k = 1; k <= 5; ++k) {
    press(m, 0.001 * k, in);
    vdm::step(m, in, s);
  }
  vdm::StepWorkspace& w = *s.work;
  const vdm::StepResultsInput input{w.K, w.mask, nullptr, nullptr, w.area_norms, w.rhs, w.a_free};
  const int which = static_cast<int>(st.range(0));
  m.compute_stress = which != 2;
  vdm::NodeMat Ku(m.n, 3);
  std::vector<double> rows(vdm::result_rows_size(m.n)), stress_scratch(4 * size_t(m.n));
  for (auto _ : st) {
    if (which == 1) {
      vdm::multiply(m.pattern, w.K, s.u, Ku);
      vdm::compute_strain_stress(m, s, stress_scratch.data());
    } else {
      const vdm::ResidualSums sums = vdm::compute_step_results(m, input, s, rows.data());
      benchmark::DoNotOptimize(sums);
    }
    benchmark::ClobberMemory();
  }
  const char* names[] = {"results pass", "multiply + compute_strain_stress", "results pass, no stress"};
  st.SetLabel(names[which]);
}
BENCHMARK(BM_StepResults)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

// A contact step (BVH refit, query, active set, solves) with a 4 mm probe 5 mm deep.
void BM_ContactStep(benchmark::State& st) {
  const vdm::TissueModel m = model(vdm::SolverMethod::structured);
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::StepInput base = vdm::make_step_input(m);
  vdm::ContactSolver contact(m);
  vdm::ContactReport report;
  std::vector<vdm::Capsule> tools(1);
  tools[0].radius = 0.004;
  double collision_ms = 0;
  long steps = 0;
  for (auto _ : st) {
    tools[0].p0 = vdm::Vec3(0.035, 0, 0.0603 - 0.005 + 0.004);
    tools[0].p1 = tools[0].p0 + vdm::Vec3(0, 0, 0.2);
    contact.step(m, base, tools, s, report);
    collision_ms += report.collision_ms;
    ++steps;
  }
  st.counters["collision_ms"] = collision_ms / std::max(1L, steps);  // BVH refit + queries
}
BENCHMARK(BM_ContactStep)->Unit(benchmark::kMillisecond);

// The bench's liver probe case (`vdmsim bench`, liver_probe): an 8 mm probe pressed into the
// liver (2.5k, 10k or 40k nodes, refresh every step, structured solver); one benchmark iteration
// is the whole 60-frame run, its time the engine time of the frames in contact. Counters:
// median ms per contact frame (wall, and CPU time of this thread: less disturbed by other
// processes on a shared machine), engine solves (active-set iterations) and Krylov
// iterations per contact frame.
void BM_LiverProbeFrames(benchmark::State& st) {
  const char* mesh = st.range(0) == 40 ? "liver_L6.obj" : st.range(0) == 10 ? "liver_L5.obj" : "liver_L4.obj";
  static vdmsim::PreparedScene ps;
  static std::string loaded;
  if (loaded != mesh) {
    ps = vdmsim::bench_probe_scene(mesh, 60, false);
    loaded = mesh;
  }
  std::vector<double> times, cpu_times;
  double solves = 0, iterations = 0;
  for (auto _ : st) {
    vdmsim::SceneSimulation sim(ps);
    double total = 0;
    for (int f = 0; f < 60; ++f) {
      const double cpu0 = thread_cpu_ms();
      sim.advance(f);
      const double cpu = thread_cpu_ms() - cpu0;
      if (sim.contact_report().nodes == 0) continue;
      total += sim.frame_step_ms();
      times.push_back(sim.frame_step_ms());
      cpu_times.push_back(cpu);
      solves += sim.contact_report().solves;
      iterations += sim.frame_iterations();
    }
    st.SetIterationTime(total / 1000.0);
  }
  const double frames = std::max<double>(1.0, double(times.size()));
  st.counters["median_ms"] = vdmsim::quantile(times, 0.5);
  st.counters["median_cpu_ms"] = vdmsim::quantile(cpu_times, 0.5);
  st.counters["p95_cpu_ms"] = vdmsim::quantile(cpu_times, 0.95);  // the frames with a second active-set solve
  st.counters["solves_per_frame"] = solves / frames;
  st.counters["krylov_its_per_frame"] = iterations / frames;
  st.SetLabel(std::to_string(ps.model.n) + " nodes");
}
BENCHMARK(BM_LiverProbeFrames)->Arg(2)->Arg(10)->Arg(40)->Iterations(3)->UseManualTime()->Unit(benchmark::kMillisecond);

// The contact's own cost in the bench's probe case (kinematic contact) and the same probe
// with penalty contact: the lazy refit (ContactSettings::lazy_refit, default) and FCL's
// refit at every query, run alternately in each benchmark iteration (both see the same
// machine load). Counters per contact frame, medians: CPU time of the whole frame (cpu_*),
// ContactReport::collision_ms (refit, walk, narrow phase: coll_*), FCL walks (queries_*),
// tree boxes refitted (boxes_*);
// ratio = median old / median new. Arg 0: mesh (2: 2.5k, 10k, 40k), arg 1: 1 = penalty,
// arg 2: ContactSettings::refit_slack in percent of the mean edge (the default: 50).
void BM_ContactRefitModes(benchmark::State& st) {
  const char* mesh = st.range(0) == 40 ? "liver_L6.obj" : st.range(0) == 10 ? "liver_L5.obj" : "liver_L4.obj";
  const bool penalty = st.range(1) == 1;
  vdmsim::PreparedScene ps[2] = {vdmsim::bench_probe_scene(mesh, 60, false), vdmsim::bench_probe_scene(mesh, 60, false)};
  for (int mode = 0; mode < 2; ++mode) {
    ps[mode].scene.contact.lazy_refit = mode == 1;
    ps[mode].scene.contact.refit_slack = 0.01 * double(st.range(2));
    if (penalty) ps[mode].scene.contact.method = vdm::ContactSettings::Method::penalty;
  }
  std::vector<double> cpu[2], coll[2];
  double queries[2] = {0, 0}, boxes[2] = {0, 0};
  for (auto _ : st) {
    for (int mode = 0; mode < 2; ++mode) {
      vdmsim::SceneSimulation sim(ps[mode]);
      for (int f = 0; f < 60; ++f) {
        const double cpu0 = thread_cpu_ms();
        sim.advance(f);
        const double t = thread_cpu_ms() - cpu0;
        if (sim.contact_report().nodes == 0) continue;
        cpu[mode].push_back(t);
        coll[mode].push_back(sim.contact_report().collision_ms);
        queries[mode] += double(sim.contact_report().queries);
        boxes[mode] += double(sim.contact_report().refit_boxes);
      }
    }
  }
  for (int mode = 0; mode < 2; ++mode) {
    const std::string tag = mode ? "_lazy" : "_fcl";
    st.counters["cpu" + tag] = vdmsim::quantile(cpu[mode], 0.5);
    st.counters["coll" + tag] = vdmsim::quantile(coll[mode], 0.5);
    st.counters["queries" + tag] = queries[mode] / std::max<double>(1.0, double(cpu[mode].size()));
    st.counters["boxes" + tag] = boxes[mode] / std::max<double>(1.0, double(cpu[mode].size()));
  }
  st.counters["coll_ratio"] = vdmsim::quantile(coll[0], 0.5) / std::max(1e-12, vdmsim::quantile(coll[1], 0.5));
  st.counters["cpu_ratio"] = vdmsim::quantile(cpu[0], 0.5) / std::max(1e-12, vdmsim::quantile(cpu[1], 0.5));
}
BENCHMARK(BM_ContactRefitModes)
    ->Args({2, 0, 50})
    ->Args({10, 0, 50})
    ->Args({40, 0, 50})
    ->Args({10, 1, 50})
    ->Args({10, 0, 0})
    ->Args({10, 0, 20})
    ->Args({10, 0, 100})
    ->Args({10, 0, 200})
    ->Args({10, 0, 400})
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

// The per-axis kernels of the structured solver on the 10k liver's K^z at rest: SpMV, IC(0)
// factorisation and apply, and the cached sparse LDL^T (factorisation, one solve).
struct AxisMatrix {
  vdm::TissueModel m = model(vdm::SolverMethod::structured);
  vdm::SpMat K;
  std::array<vdm::SpMat, 3> K3;
  vdm::AxisStiffness edge_k;  // the same K as edge weights and diagonals (the solver's input)
  vdm::FlagMat held;          // nodes held on every axis
  AxisMatrix() {
    vdm::NodeMat a(m.n, 3);
    vdm::Vec v(m.n);
    vdm::distributed_area_vectors(m.rest.positions, m.rest.triangles, a);
    const vdm::VolumeScale how =
        vdm::distributed_volumes(a, vdm::enclosed_volume(m.rest.positions, m.rest.triangles, vdm::Vec3::Zero()), v);
    std::array<vdm::SpMat, 3> k3 = {m.pattern.matrix, m.pattern.matrix, m.pattern.matrix};
    vdm::assemble_stiffness(m, a, v, vdm::Vec(), k3);
    K = k3[2];
    K3 = k3;
    vdm::Vec norms(m.n), scratch(m.n);
    for (int i = 0; i < m.n; ++i) norms[i] = a.row(i).norm();
    edge_k = {vdm::Vec(Eigen::Index(m.edges.size())), vdm::NodeMat(m.n, 3)};
    vdm::assemble_stiffness(m, a, norms, v, how, vdm::Vec(), edge_k, scratch);
    // About as many held nodes as under the bench's probe: the 60 lowest.
    held = vdm::FlagMat::Zero(m.n, 3);
    std::vector<int> order(size_t(m.n));
    for (int i = 0; i < m.n; ++i) order[size_t(i)] = i;
    std::sort(order.begin(), order.end(), [&](int i, int j) { return m.rest.positions(i, 2) < m.rest.positions(j, 2); });
    for (int k = 0; k < 60 && k < m.n; ++k) held.row(order[size_t(k)]).setOnes();
  }
};

void BM_AxisKernels(benchmark::State& st) {
  static const AxisMatrix am;
  const int n = am.m.n;
  vdm::Vec x = vdm::Vec::Ones(n), y(n);
  vdm::IncompleteCholesky ic;
  ic.analyze(am.K);
  ic.factorize(am.K);
  vdm::SparseLdlt ldlt;
  ldlt.analyze(am.K);
  ldlt.factorize(am.K);
  const int which = static_cast<int>(st.range(0));
  for (auto _ : st) {
    switch (which) {
      case 0: vdm::symmetric_multiply(am.K, x.data(), y.data()); break;
      case 1: ic.factorize(am.K); break;
      case 2: ic.apply(x.data(), y.data()); break;
      case 3: ldlt.factorize(am.K); break;
      default: ldlt.solve(x.data(), y.data()); break;
    }
    benchmark::DoNotOptimize(y.data());
  }
  const char* names[] = {"spmv", "ic0_factorize", "ic0_apply", "ldlt_factorize", "ldlt_solve"};
  st.SetLabel(std::string(names[which]) + (which >= 3 ? " (L nnz " + std::to_string(ldlt.factor_nonzeros()) + ")" : ""));
}
BENCHMARK(BM_AxisKernels)->DenseRange(0, 4)->Unit(benchmark::kMicrosecond);

// The same kernels on the three axes together (engine/axis_matrices, axis_incomplete_cholesky:
// what the structured solver runs), in its reverse Cuthill-McKee order: one product or IC(0)
// apply on a block of 3 vectors (r) or 6 (r and s), the IC(0) factorisation of all three
// axes (plain and modified), the gather of their values. Compare with 3x (or 6x) the single-axis figures of BM_AxisKernels.
void BM_ThreeAxisKernels(benchmark::State& st) {
  static const AxisMatrix am;
  const int n = am.m.n;
  static vdm::AxisMatrices K;
  static vdm::AxisIncompleteCholesky ic;
  if (K.n != n) {
    K.analyze(am.m.pattern, vdm::reverse_cuthill_mckee(am.m.pattern.matrix));
    K.gather(am.edge_k, vdm::FlagMat::Zero(n, 3), nullptr);  // the matrices of am.K3
    ic.analyze(K);
  }
  ic.factorize(K);
  std::vector<double> x(6 * size_t(n), 1.0), y(6 * size_t(n));
  double dot[6];
  const int which = static_cast<int>(st.range(0));
  for (auto _ : st) {
    switch (which) {
      case 0: vdm::multiply_block<3>(K, x.data(), y.data(), dot); break;
      case 1: vdm::multiply_block<6>(K, x.data(), y.data(), dot); break;
      case 2: ic.apply<3>(x.data(), y.data(), dot); break;
      case 3: ic.apply<6>(x.data(), y.data(), dot); break;
      case 4: ic.factorize(K); break;
      case 5: K.gather(am.edge_k, am.held, nullptr); break;
      default: ic.factorize(K, 0.9); break;
    }
    benchmark::DoNotOptimize(y.data());
    benchmark::DoNotOptimize(dot);
  }
  const char* names[] = {"spmv x3",       "spmv x6",       "ic0_apply x3", "ic0_apply x6", "ic0_factorize 3 axes",
                         "gather 3 axes (the solver's: edge weights, 60 held nodes)", "mic0_factorize 3 axes (omega 0.9, the solver's)"};
  const bool six = which == 1 || which == 3;  // the kernels with AVX2 variants (engine/simd4.hpp)
  st.SetLabel(std::string(names[which]) + (six ? (vdm::simd::avx2_enabled() ? " (AVX2)" : " (SSE2)") : ""));
}
BENCHMARK(BM_ThreeAxisKernels)->DenseRange(0, 6)->Unit(benchmark::kMicrosecond);

// The blocks of 6 on the SSE2 kernels (forced), for comparison with BM_ThreeAxisKernels/1
// and /3 where the CPU runs their AVX2 variants.
void BM_ThreeAxisKernelsSse2(benchmark::State& st) {
  const bool saved = vdm::simd::avx2_enabled();
  vdm::simd::set_avx2(false);
  BM_ThreeAxisKernels(st);
  vdm::simd::set_avx2(saved);
}
BENCHMARK(BM_ThreeAxisKernelsSse2)->Arg(1)->Arg(3)->Unit(benchmark::kMicrosecond);


// What the contact broad phase costs without a BVH: the exact node-versus-capsule distance of
// every node (the narrow phase's own test), for comparison with BM_ContactStep's collision_ms.
void BM_AllNodesAgainstCapsule(benchmark::State& st) {
  const vdm::SurfaceMesh& mesh = liver();
  vdm::Capsule c;
  c.radius = 0.004;
  c.p0 = vdm::Vec3(0.035, 0, 0.0593);
  c.p1 = c.p0 + vdm::Vec3(0, 0, 0.2);
  std::vector<int> near;
  near.reserve(static_cast<size_t>(mesh.node_count()));
  for (auto _ : st) {
    near.clear();
    for (int i = 0; i < mesh.node_count(); ++i) {
      vdm::Vec3 p, nrm;
      if (vdm::capsule_distance(c, mesh.positions.row(i).transpose(), p, nrm) < 0.001) near.push_back(i);
    }
    benchmark::DoNotOptimize(near.data());
  }
  st.counters["nodes_found"] = double(near.size());
}
BENCHMARK(BM_AllNodesAgainstCapsule)->Unit(benchmark::kMicrosecond);

void BM_StressViewScalarAndColour(benchmark::State& st) {
  const vdm::TissueModel m = model(vdm::SolverMethod::structured);
  vdm::SimState s = vdm::make_sim_state(m);
  vdm::StepInput in = vdm::make_step_input(m);
  press(m, 0.01, in);
  vdm::step(m, in, s);
  std::vector<float> field;
  std::vector<render::Rgb8> colours(static_cast<size_t>(m.n));
  for (auto _ : st) {
    render::scalar_field(render::Quantity::stress_magnitude, s, field);
    for (size_t i = 0; i < field.size(); ++i) colours[i] = render::colormap(render::ColorMapName::viridis, field[i] / 5000.0);
    benchmark::DoNotOptimize(colours.data());
  }
}
BENCHMARK(BM_StressViewScalarAndColour)->Unit(benchmark::kMicrosecond);

void BM_PngEncode720p(benchmark::State& st) {
  render::Image im(1280, 720);
  for (int y = 0; y < 720; ++y)
    for (int x = 0; x < 1280; ++x) {
      std::uint8_t* p = im.pixel(x, y);
      p[0] = std::uint8_t(120 + 60 * (x > 400 && x < 900 && y > 200 && y < 600));
      p[1] = std::uint8_t(130 + y / 8);
      p[2] = std::uint8_t(140 + x / 16);
      p[3] = 255;
    }
  const std::string path = std::string(VDMSIM_BUILD_DIR) + "/micro_benchmark_frame.png";
  std::string error;
  for (auto _ : st) render::write_png(path, im, static_cast<int>(st.range(0)), false, error);
  std::remove(path.c_str());
}
BENCHMARK(BM_PngEncode720p)->Arg(1)->Arg(6)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
