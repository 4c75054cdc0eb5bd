#include "app/cli/commands.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "app/check/scene_sanity.hpp"
#include "app/mesh_prep/self_intersections.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/scene/scan_like_organ.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"
#include "app/studies/paper_cube.hpp"
#include "app/studies/paper_plots.hpp"
#include "app/studies/paper_beam.hpp"
#include "app/studies/calibrate.hpp"
#include "app/simulation/tet_mesher.hpp"
#include "engine/geometry.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {

namespace {
// The size and volume in the file's units and, after `scale`, in metres and litres; a note
// when the organ would be over 1 m or under 1 cm across, with the --scale that fits.
void print_units(const vdm::Vec3& lo, const vdm::Vec3& hi, double volume, double scale, std::ostream& out) {
  const vdm::Vec3 size = hi - lo;
  const double s3 = scale * scale * scale;
  out << "in file units: size " << size.x() / scale << " x " << size.y() / scale << " x " << size.z() / scale;
  if (volume >= 0) out << ", volume " << volume / s3;
  out << "\n";
  out << "in metres:  size " << size.x() << " x " << size.y() << " x " << size.z() << " m";
  if (volume >= 0) out << ", volume " << volume * 1000 << " litres";
  out << " (after --scale " << scale << ")\n";
  const double extent = size.maxCoeff();
  if (extent > 1.0 || extent < 0.01) {
    double fit = scale;
    for (double f : {1e-3, 1e-2, 1e-1, 1e1, 1e2, 1e3, 1e-6, 1e6})
      if (extent * f >= 0.03 && extent * f <= 0.6) {
        fit = scale * f;
        break;
      }
    out << "note:       " << extent << " m across is " << (extent > 1.0 ? "over 1 m" : "under 1 cm")
        << ": implausible for an organ";
    if (fit != scale) {
      out << "; --scale " << fit << " makes it " << extent * fit / scale << " m";
      if (std::abs(fit - 1e-3) < 1e-12) out << " (the file in millimetres)";
      if (std::abs(fit - 1e-2) < 1e-12) out << " (the file in centimetres)";
      if (std::abs(fit - 1) < 1e-12) out << " (the file in metres)";
    }
    out << "\n";
  }
}
}  // namespace

int cmd_mesh_info(const std::string& path, double scale, std::ostream& out, std::ostream& err) {
  MeshLoadOptions opt;
  opt.scale = scale;
  opt.validate = false;
  MeshLoadResult r = load_surface_mesh(path, opt);
  if (!r.ok) {
    err << "vdmsim: error: " << r.error << "\n";
    return 2;
  }
  vdm::SurfaceMesh oriented = r.mesh;
  const vdm::MeshCheck check = vdm::check_and_orient_surface(oriented);
  const vdm::NodeMat& x = oriented.positions;
  const vdm::Vec3 lo = x.colwise().minCoeff(), hi = x.colwise().maxCoeff();
  out << "file:       " << path << "\n";
  out << "nodes:      " << r.mesh.node_count() << "\n";
  out << "triangles:  " << r.mesh.triangle_count() << "\n";
  const bool closed = vdm::is_closed(r.mesh.triangles);
  out << "closed:     " << (closed ? "yes" : "no") << "\n";
  out << std::setprecision(6);
  if (check.ok())
    out << "volume:     " << vdm::enclosed_volume(x, oriented.triangles, x.colwise().mean().transpose()) << "\n";
  else
    out << "volume:     n/a (" << vdm::to_string(check.problem) << ")\n";
  out << "area:       " << vdm::surface_area(x, oriented.triangles) << "\n";
  out << "bbox min:   " << lo.x() << " " << lo.y() << " " << lo.z() << "\n";
  out << "bbox max:   " << hi.x() << " " << hi.y() << " " << hi.z() << "\n";
  out << "bbox size:  " << (hi - lo).x() << " " << (hi - lo).y() << " " << (hi - lo).z() << "\n";
  print_units(lo, hi, check.ok() ? vdm::enclosed_volume(x, oriented.triangles, x.colwise().mean().transpose()) : -1, scale,
              out);
  if (r.welded_nodes) out << "welded:     " << r.welded_nodes << " coincident vertices merged\n";
  if (r.dropped_nodes) out << "dropped:    " << r.dropped_nodes << " unreferenced vertices\n";
  if (check.flipped) {
    out << "note:       the surface was oriented inward; it is used flipped outward\n";
    err << "vdmsim: warning: " << flipped_surface_note(path) << "\n";
  }
  if (!check.ok()) {
    out << "valid organ: no\n";
    err << "vdmsim: error: " << path << ": " << vdm::to_string(check.problem) << ": " << check.message << "\n";
    return 2;
  }
  const SelfIntersections crossing = find_self_intersections(oriented, 10);
  if (crossing.any) {
    out << "crossings:  " << crossing.pairs.size() << (crossing.pairs.size() >= 10 ? " or more" : "")
        << " pairs of triangles pass through each other\n";
    for (const auto& [a, b] : crossing.pairs) {
      const vdm::Vec3 c = (x.row(oriented.triangles(a, 0)) + x.row(oriented.triangles(a, 1)) + x.row(oriented.triangles(a, 2))) / 3;
      out << "            triangles " << a << " and " << b << " (near " << c.x() << " " << c.y() << " " << c.z() << ")\n";
    }
    out << "valid organ: no\n";
    err << "vdmsim: error: " << path << ": self-intersection: the surface passes through itself (" << crossing.text()
        << "); `vdmsim prepare-mesh` repairs it\n";
    return 2;
  }
  out << "valid organ: yes\n";
  return 0;
}


int cmd_check(const std::string& scene_path, std::ostream& out, std::ostream& err) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  const bool ok = prepare_scene(scene_path, ps, problems);
  if (!ok) {
    report_problems(problems, err);
    return 2;
  }
  const SanityReport sanity = scene_sanity(ps);
  problems.insert(problems.end(), sanity.problems.begin(), sanity.problems.end());
  if (!report_problems(problems, err)) return 2;
  out << scene_path << ": ok (" << ps.surface.node_count() << " nodes, " << ps.scene.frames << " frames of " << ps.scene.dt
      << " s, effects:";
  for (Effect e : ps.scene.effects) out << ' ' << to_string(e);
  out << ")\n";
  print_sanity(ps, sanity, out);
  return 0;
}

int cmd_run(const std::string& scene_path, const RunOptions& options, std::ostream& out, std::ostream& err, bool terminal) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  const bool ok = prepare_scene(scene_path, ps, problems);
  if (!report_problems(problems, err) || !ok) return 2;
  return run_scene(ps, options, out, err, terminal);
}

int cmd_run(const std::string& scene_path, const std::string& out_dir, int frames, bool render, bool video, bool resume, int checkpoint_every, std::ostream& out,
            std::ostream& err, bool terminal) {
  RunOptions opt;
  opt.out_dir = out_dir;
  opt.frames = frames;
  opt.render = render;
  opt.video = video;
  opt.resume = resume;
  opt.checkpoint_every = checkpoint_every;
  return cmd_run(scene_path, opt, out, err, terminal);
}

namespace {
int write_scan_like(int level, const std::string& out_path, std::ostream& out, std::ostream& err) {
  ScanLikeOptions opt;
  opt.level = level;
  const vdm::SurfaceMesh mesh = make_scan_like_liver(opt);
  std::ostringstream header;
  header << "vdmsim liver as a CT segmentation gives it, by `vdmsim make-organ liver --scan-like --level " << level
         << "`\nunits: millimetres, scanner coordinates; bumpy, cropped open, folded through itself: "
            "run `vdmsim prepare-mesh` on it";
  std::string error;
  bool at_run_time = false;  // a full disk: exit 1
  if (!prepare_output_file_folder(out_path, error, &at_run_time) ||
      !save_obj(mesh, out_path, header.str(), error, &at_run_time)) {
    err << "vdmsim: error: " << error << "\n";
    return at_run_time ? 1 : 2;
  }
  const vdm::Vec3 lo = mesh.positions.colwise().minCoeff(), hi = mesh.positions.colwise().maxCoeff();
  out << "scan-like liver level " << level << ": " << mesh.node_count() << " nodes, " << mesh.triangle_count()
      << " triangles, size " << (hi - lo).x() << " x " << (hi - lo).y() << " x " << (hi - lo).z()
      << " mm (open, self-intersecting) -> " << out_path << "\n";
  return 0;
}
}  // namespace

int cmd_make_organ(const std::string& organ, int level, const std::string& out_path, std::ostream& out,
                   std::ostream& err, bool scan_like) {
  if (organ != "liver" && organ != "gallbladder") {
    err << "vdmsim: error: unknown organ '" << organ << "' (expected liver or gallbladder)\n";
    return 2;
  }
  if (scan_like && organ != "liver") {
    err << "vdmsim: error: --scan-like makes a liver only\n";
    return 2;
  }
  if (level < 1 || level > 7) {
    err << "vdmsim: error: --level " << level << " is out of range (1 to 7; 4, 5, 6 give 2562, 10242, 40962 nodes)\n";
    return 2;
  }
  if (scan_like) return write_scan_like(level, out_path, out, err);
  vdm::SurfaceMesh mesh = organ == "liver" ? make_liver_mesh(level) : make_gallbladder_mesh(level);
  const vdm::MeshCheck check = vdm::check_and_orient_surface(mesh);
  if (!check.ok() || check.flipped) {
    err << "vdmsim: error: generated " << organ << " is not a valid outward surface: " << check.message << "\n";
    return 1;
  }
  // Smallest triangle quality (2 inradius / circumradius, 1 = equilateral).
  double worst = 1.0;
  for (int k = 0; k < mesh.triangle_count(); ++k) {
    const vdm::Vec3 a = mesh.positions.row(mesh.triangles(k, 0)), b = mesh.positions.row(mesh.triangles(k, 1)),
                    c = mesh.positions.row(mesh.triangles(k, 2));
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
    const double s = 0.5 * (la + lb + lc);
    const double area = (b - a).cross(c - a).norm() / 2;
    worst = std::min(worst, 8 * area * area / (s * la * lb * lc));
  }
  const vdm::Vec3 lo = mesh.positions.colwise().minCoeff(), hi = mesh.positions.colwise().maxCoeff();
  const double volume = vdm::enclosed_volume(mesh.positions, mesh.triangles, mesh.positions.colwise().mean().transpose());
  std::ostringstream header;
  header << "vdmsim " << organ << ", generated by `vdmsim make-organ " << organ << " --level " << level
         << "` (app/scene/organ_generator.cpp)\n"
         << "units: metres; nodes " << mesh.node_count() << ", triangles " << mesh.triangle_count();
  std::string error;
  bool at_run_time = false;  // a full disk: exit 1
  if (!prepare_output_file_folder(out_path, error, &at_run_time) ||
      !save_obj(mesh, out_path, header.str(), error, &at_run_time)) {
    err << "vdmsim: error: " << error << "\n";
    return at_run_time ? 1 : 2;
  }
  out << organ << " level " << level << ": " << mesh.node_count() << " nodes, " << mesh.triangle_count()
      << " triangles, volume " << volume * 1e6 << " cm^3, size " << (hi - lo).x() * 100 << " x "
      << (hi - lo).y() * 100 << " x " << (hi - lo).z() * 100 << " cm, worst triangle quality " << worst
      << " -> " << out_path << "\n";
  return 0;
}

int cmd_paper(const std::string& experiment, const std::string& out_dir, std::ostream& out,
              std::ostream& err) {
  const bool all = experiment == "all";
  std::vector<BeamCase> beams;
  if (all || experiment == "beam-stretch") beams.push_back(BeamCase::stretch);
  if (all || experiment == "beam-bend") beams.push_back(BeamCase::bend);
  if (all || experiment == "beam-twist") beams.push_back(BeamCase::twist);
  if (!all && experiment != "cube-stress" && experiment != "anisotropy" && beams.empty()) {
    err << "vdmsim: error: unknown experiment '" << experiment
        << "' (expected cube-stress, anisotropy, beam-stretch, beam-bend, beam-twist or all)\n";
    return 2;
  }
  std::string error;
  if (!prepare_output_dir(out_dir, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  namespace fs = std::filesystem;
  const CubeCompression cfg;
  if (all || experiment == "cube-stress") {
    const auto t0 = vdm::Clock::now();
    const CubeResult r = run_cube_stress(cfg);
    const std::string path = (fs::path(out_dir) / "cube-stress.csv").string();
    if (!write_cube_stress_csv(path, r, error) ||
        !write_cube_stress_plot((fs::path(out_dir) / "cube-stress.png").string(), r, cfg, error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
    double worst = 0;
    for (double v : r.volume_rel_error) worst = std::max(worst, std::abs(v));
    out << "cube-stress: " << r.volume_rel_error.size() - 1 << " steps, " << cfg.compression * 100
        << " % compression, max |volume error| " << worst << ", "
        << vdm::ms_since(t0) / 1000 << " s -> "
        << path << " and cube-stress.png\n";
  }
  if (all || experiment == "anisotropy") {
    const auto t0 = vdm::Clock::now();
    const std::vector<AnisotropyCase> cases = {AnisotropyCase::uniform, AnisotropyCase::x_infinite,
                                               AnisotropyCase::prefer_y};
    std::vector<CubeResult> results;
    for (AnisotropyCase c : cases) results.push_back(run_anisotropy(cfg, c));
    const std::string path = (fs::path(out_dir) / "anisotropy.csv").string();
    if (!write_anisotropy_csv(path, cases, results, error) ||
        !write_anisotropy_plot((fs::path(out_dir) / "anisotropy.png").string(), cases, results, cfg, error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
    out << "anisotropy: 3 cases x " << results[0].volume_rel_error.size() - 1 << " steps, "
        << vdm::ms_since(t0) / 1000 << " s -> "
        << path << "\n";
    for (size_t c = 0; c < cases.size(); ++c) {
      const auto& p = results[c].points;
      out << "  " << std::setw(10) << to_string(cases[c]) << ": final uB_y = " << p[1].displacement.back().y()
          << " m, uC_x = " << p[2].displacement.back().x() << " m, uA_z = " << p[0].displacement.back().z()
          << " m\n";
    }
  }
  if (!beams.empty()) return paper_beams(beams, BeamConfig{}, out_dir, out, err);
  return 0;
}

int paper_beams(const std::vector<BeamCase>& beams, const BeamConfig& cfg, const std::string& out_dir,
                std::ostream& out, std::ostream& err) {
  namespace fs = std::filesystem;
  const auto t0 = vdm::Clock::now();
  const BeamStudy study = run_beam_study(cfg, beams);
  out << "beam " << cfg.length * 100 << " x " << cfg.width * 100 << " x " << cfg.width * 100 << " cm, "
      << cfg.cells_across << " x " << cfg.cells_along << " cells (" << 24 * cfg.cells_across * cfg.cells_across * cfg.cells_along
      << " tets), FEM E = " << cfg.young << " Pa, nu = " << cfg.poisson << "; VDM B = " << study.used.bulk
      << " Pa, B_ij = " << study.used.connectivity << " Pa" << (cfg.calibrate ? " (fitted)" : "") << "\n";
  for (const BeamCaseResult& r : study.cases) {
    std::string error;
    const std::string path = (fs::path(out_dir) / ("beam-" + std::string(to_string(r.which)) + ".csv")).string();
    if (!write_beam_csv(path, r, error) ||
        !write_beam_plot((fs::path(out_dir) / ("beam-" + std::string(to_string(r.which)) + ".png")).string(), r, error)) {
      err << "vdmsim: error: " << error << "\n";
      return 1;
    }
    double vv = 0, vf = 0;
    for (double v : r.vdm.volume_rel) vv = std::max(vv, std::abs(v));
    for (double v : r.fem.volume_rel) vf = std::max(vf, std::abs(v));
    out << "beam-" << to_string(r.which) << ": " << r.fem.u.size() - 1 << " steps, mean |u| difference VDM vs FEM "
        << 100 * r.mean_relative_difference << " %, max |volume change| VDM " << vv << ", FEM " << vf
        << (r.fem.converged ? "" : " (FEM did not converge on every step)") << " -> " << path << "\n";
  }
  std::string error;
  if (!write_beam_volume_plot((fs::path(out_dir) / "beam-volume.png").string(), study.cases, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << "beam experiments: " << vdm::ms_since(t0) / 1000 << " s\n";
  return 0;
}

}  // namespace vdmsim

namespace vdmsim {

int cmd_calibrate(const std::string& mesh_path, double scale, double young, double poisson, int steps, double tet_size,
                  const std::string& out_path, std::ostream& out, std::ostream& err) {
  if (!(young > 0)) {
    err << "vdmsim: error: --young " << young << " is out of range: expected > 0 (Pa)\n";
    return 2;
  }
  if (!(poisson >= 0 && poisson < 0.5)) {
    err << "vdmsim: error: --poisson " << poisson << " is out of range: expected >= 0 and < 0.5\n";
    return 2;
  }
  if (steps < 1) {
    err << "vdmsim: error: --steps must be >= 1\n";
    return 2;
  }
  MeshLoadOptions mopt;
  mopt.scale = scale;
  const MeshLoadResult mesh = load_surface_mesh(mesh_path, mopt);
  if (!mesh.ok) {
    err << "vdmsim: error: " << mesh.error << "\n";
    return 2;
  }
  if (mesh.flipped) err << "vdmsim: warning: " << flipped_surface_note(mesh_path) << "\n";
  const auto t0 = vdm::Clock::now();
  vdm::fem::TetMesh tets;
  std::string error;
  // The FEM keeps the surface's triangles; inside, tets grow to `tet_size` (by default a tenth
  // of the organ's smallest extent: the load cases deform it smoothly on that scale). Graded
  // from a 10k-node surface instead, the FEM had 48k nodes and took minutes per factorisation.
  const vdm::Vec3 extent = mesh.mesh.positions.colwise().maxCoeff() - mesh.mesh.positions.colwise().minCoeff();
  const double interior = tet_size > 0 ? tet_size : 0.1 * extent.minCoeff();
  err << "calibrate: " << mesh.mesh.node_count() << " surface nodes; tetrahedralising for the FEM reference (inside up to "
      << 1000 * interior << " mm)\n";
  if (!tetrahedralize(mesh.mesh, interior, tets, error, TetInterior::coarse)) {
    err << "vdmsim: error: " << mesh_path << ": " << error << "\n";
    return 1;
  }
  err << "calibrate: " << tets.node_count() << " nodes, " << tets.tet_count() << " tets (" << vdm::ms_since(t0) / 1000
      << " s); two FEM load cases, then about 25 VDM runs of both\n";
  OrganCalibration calibration;
  const CalibrationProgress progress = [&err](const std::string& line) { err << line << "\n" << std::flush; };
  if (!calibrate_organ(mesh.mesh, tets, young, poisson, steps, calibration, progress)) {
    err << "vdmsim: error: " << mesh_path << ": no node in the top patch to drive\n";
    return 1;
  }
  const CalibrationResult& r = calibration.fit;
  const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
  if (!parent.empty() && !prepare_output_dir(parent.string(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  if (!write_calibration_yaml(out_path, r, young, poisson, mesh_path, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  out << mesh_path << ": " << tets.node_count() << " nodes, " << tets.tet_count() << " tets; fitted bulk_modulus "
      << r.params.bulk << " Pa, connectivity_modulus " << r.params.connectivity << " Pa; RMS displacement difference "
      << 100 * r.rms_displacement << " % of the largest, mean |u| difference press " << 100 * r.mean_relative_difference[0]
      << " %, pull " << 100 * r.mean_relative_difference[1] << " %; "
      << vdm::ms_since(t0) / 1000 << " s -> " << out_path << "\n";
  // How the documented E, nu rule does on this organ, beside the fit.
  const CalibrationResult& by_rule = calibration.rule;
  out << "  the E, nu rule (docs/model.md) gives bulk_modulus " << by_rule.params.bulk << " Pa, connectivity_modulus "
      << by_rule.params.connectivity << " Pa: RMS displacement difference " << 100 * by_rule.rms_displacement
      << " % of the largest, RMS work difference " << 100 * by_rule.rms_work << " % (the fit: " << 100 * r.rms_work
      << " %)\n";
  return 0;
}

}  // namespace vdmsim
