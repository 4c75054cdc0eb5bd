#include "app/mesh_prep/prepare_mesh.hpp"

#include <cmath>
#include <filesystem>
#include <exception>
#include <iomanip>
#include <sstream>

#include "app/mesh_prep/mesh_quality.hpp"
#include "app/mesh_prep/self_intersections.hpp"
#include "app/mesh_prep/surface_distance.hpp"
#include "app/mesh_prep/surface_repair.hpp"
#include "app/run/output_dir.hpp"
#include "app/scene/mesh_io.hpp"
#include "engine/mesh_topology.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {

double edge_length_for_nodes(double area, int nodes) {
  return std::sqrt(2.0 * area / (std::sqrt(3.0) * nodes));
}

double nodes_for_edge_length(double area, double edge) { return 2.0 * area / (std::sqrt(3.0) * edge * edge); }

namespace {

constexpr double kMinAngleTarget = 20.0;    // degrees
constexpr double kVolumeTarget = 0.02;      // relative change
constexpr double kDistanceTarget = 1.5e-3;  // m, mean

std::string volume_text(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v * 1e6 << " cm^3";
  return s.str();
}

void print_row(std::ostream& out, const std::string& what, const MeshQuality& q, bool volume_known) {
  out << std::setprecision(4) << "  " << std::left << std::setw(9) << what << std::right << std::setw(7) << q.nodes
      << " nodes " << std::setw(7) << q.triangles << " triangles  volume "
      << (volume_known ? volume_text(q.volume) : std::string("n/a (not closed)")) << "  smallest angle "
      << q.smallest_angle_deg << " deg  mean edge " << q.mean_edge * 1000 << " mm\n";
}

int prepare_mesh(const PrepareMeshOptions& opt, std::ostream& out, std::ostream& err) {
  const auto t0 = vdm::Clock::now();
  auto progress = [&](const std::string& line) {
    out << "[" << std::fixed << std::setprecision(1) << vdm::ms_since(t0) / 1000 << " s] " << line << "\n" << std::defaultfloat;
    out.flush();
  };
  if (opt.nodes != 0 && opt.edge_length != 0) {
    err << "vdmsim: error: give --nodes or --edge-length, not both\n";
    return 2;
  }
  if (opt.nodes < 0 || (opt.nodes > 0 && opt.nodes < 100) || opt.nodes > kMaxPreparedNodes) {
    err << "vdmsim: error: --nodes " << opt.nodes << " is out of range (100 to " << kMaxPreparedNodes << ")\n";
    return 2;
  }
  if (opt.out.empty()) {
    err << "vdmsim: error: --out: empty: name the OBJ file to write\n";
    return 2;
  }
  // The scan is the user's only copy: the result never replaces it.
  if (is_or_lies_inside(opt.out, opt.in)) {
    err << "vdmsim: error: --out " << opt.out << " is the input " << opt.in
        << ": prepare-mesh would overwrite it; choose another file\n";
    return 2;
  }
  if (opt.edge_length < 0 || !std::isfinite(opt.edge_length)) {
    err << "vdmsim: error: --edge-length must be a positive length in metres\n";
    return 2;
  }
  if (!(opt.smoothing >= 0) || opt.smoothing > 100) {
    err << "vdmsim: error: --smoothing " << opt.smoothing << " is out of range (0 to 100)\n";
    return 2;
  }
  if (!(opt.scale > 0) || !std::isfinite(opt.scale)) {
    err << "vdmsim: error: --scale must be a positive number (0.001 for millimetres)\n";
    return 2;
  }
  progress("reading " + opt.in);
  MeshLoadOptions lopt;
  lopt.scale = opt.scale;
  lopt.validate = false;
  const MeshLoadResult loaded = load_surface_mesh(opt.in, lopt);
  if (!loaded.ok) {
    err << "vdmsim: error: " << loaded.error << "\n";
    return 2;
  }
  const vdm::SurfaceMesh& input = loaded.mesh;
  vdm::SurfaceMesh oriented = input;
  const bool input_valid = vdm::check_and_orient_surface(oriented).ok();
  const MeshQuality before = measure_mesh(input_valid ? oriented : input);

  vdm::SurfaceMesh repaired = input;
  RepairReport rep;
  const bool repaired_ok = repair_surface(repaired, rep, progress);
  out << "repair: " << rep.soup_triangles_removed << " duplicate or degenerate triangles removed, "
      << rep.components_dropped << " loose pieces dropped, " << rep.holes_filled << " holes filled";
  if (rep.holes_filled) out << " (the largest with " << rep.largest_hole_edges << " edges)";
  out << ", " << rep.self_intersections << " crossing triangle pairs"
      << (rep.self_intersections ? (rep.self_intersections_left ? " (some remain)" : " removed: " + rep.crossings_method) : "")
      << "\n";
  if (!repaired_ok) {
    err << "vdmsim: error: " << opt.in << ": cannot be repaired into a closed organ surface: " << rep.error << "\n";
    return 2;
  }
  const MeshQuality fixed = measure_mesh(repaired);
  if (!(fixed.volume > 0)) {
    err << "vdmsim: error: " << opt.in << ": the repaired surface encloses no volume\n";
    return 2;
  }

  // An edge far below the surface's size would remesh for hours: refused by the node count it
  // gives over the area, as --nodes is.
  if (opt.edge_length > 0 && nodes_for_edge_length(fixed.area, opt.edge_length) > kMaxPreparedNodes) {
    err << std::setprecision(3) << "vdmsim: error: --edge-length " << opt.edge_length << " m over the surface's "
        << fixed.area << " m^2 would give about " << nodes_for_edge_length(fixed.area, opt.edge_length)
        << " nodes, more than " << kMaxPreparedNodes << ": give at least "
        << edge_length_for_nodes(fixed.area, kMaxPreparedNodes) << " m\n";
    return 2;
  }
  const int target_nodes = opt.edge_length > 0 ? 0 : (opt.nodes > 0 ? opt.nodes : 10000);
  double L = opt.edge_length > 0 ? opt.edge_length : edge_length_for_nodes(fixed.area, target_nodes);
  const double extent = (fixed.hi - fixed.lo).maxCoeff();
  if (L > extent / 4) {
    err << "vdmsim: error: an edge of " << L << " m is too long for a surface " << extent << " m across\n";
    return 2;
  }
  RemeshOptions ropt;
  ropt.iterations = opt.iterations;
  ropt.smoothing = opt.smoothing;
  vdm::SurfaceMesh prepared;
  for (int attempt = 0; attempt < 2; ++attempt) {
    prepared = repaired;
    ropt.edge_length = L;
    std::string error;
    if (!remesh_surface(prepared, ropt, error, progress)) {
      err << "vdmsim: error: " << opt.in << ": remeshing failed: " << error << "\n";
      return 1;
    }
    const int got = prepared.node_count();
    if (target_nodes == 0 || std::abs(got - target_nodes) < 0.03 * target_nodes) break;
    std::ostringstream s;
    s << "remesh: " << got << " nodes for a target of " << target_nodes << "; again with the edge corrected";
    progress(s.str());
    L *= std::sqrt(double(got) / target_nodes);
  }
  vdm::Vec3 shift = vdm::Vec3::Zero();
  if (opt.center) {
    const MeshQuality q = measure_mesh(prepared);
    shift = -0.5 * (q.lo + q.hi);
    prepared.positions.rowwise() += shift.transpose();
  }

  progress("checking the result");
  vdm::SurfaceMesh checked = prepared;
  const vdm::MeshCheck check = vdm::check_and_orient_surface(checked);
  if (!check.ok()) {
    err << "vdmsim: error: " << opt.in << ": the prepared surface is not a valid organ: " << check.message << "\n";
    return 1;
  }
  prepared = checked;
  const SelfIntersections si = find_self_intersections(prepared);
  if (si.any) {
    err << "vdmsim: error: " << opt.in << ": the prepared surface passes through itself (" << si.text() << ")\n";
    return 1;
  }
  progress("measuring the distance to the input");
  vdm::SurfaceMesh input_placed = input, repaired_placed = repaired;
  input_placed.positions.rowwise() += shift.transpose();
  repaired_placed.positions.rowwise() += shift.transpose();
  const SurfaceDistance to_input = sampled_distance(prepared, repaired_placed);
  const SurfaceDistance from_input = sampled_distance(input_placed, prepared);
  const MeshQuality after = measure_mesh(prepared);

  // The output's folder, made when missing; a full disk is a failure at run time (exit 1).
  std::string error;
  bool at_run_time = false;
  if (!prepare_output_file_folder(opt.out, error, &at_run_time)) {
    err << "vdmsim: error: " << error << "\n";
    return at_run_time ? 1 : 2;
  }
  std::ostringstream header;
  header << "prepared by `vdmsim prepare-mesh` from " << std::filesystem::path(opt.in).filename().string()
         << " (scale " << opt.scale << ")\nunits: metres; nodes " << after.nodes << ", triangles " << after.triangles;
  if (opt.center) header << "\nmoved by " << shift.x() << " " << shift.y() << " " << shift.z() << " m (centred)";
  if (!save_obj(prepared, opt.out, header.str(), error, &at_run_time)) {
    err << "vdmsim: error: " << error << "\n";
    return at_run_time ? 1 : 2;
  }

  const double volume_change = (after.volume - fixed.volume) / fixed.volume;
  out << "before and after (metres after --scale " << std::setprecision(6) << opt.scale << "):\n";
  print_row(out, "input", before, input_valid);
  print_row(out, "repaired", fixed, true);
  print_row(out, "prepared", after, true);
  out << std::setprecision(3) << "volume change: " << 100 * volume_change << " % (prepared against repaired";
  if (input_valid) out << "; " << 100 * (after.volume - before.volume) / before.volume << " % against the input";
  out << ")\n";
  out << "distance: prepared to repaired input: mean " << to_input.mean * 1000 << " mm, max " << to_input.max * 1000
      << " mm; input to prepared: mean " << from_input.mean * 1000 << " mm, max " << from_input.max * 1000 << " mm\n";
  if (opt.center) out << "centred: moved by " << shift.x() << " " << shift.y() << " " << shift.z() << " m\n";
  const double mean_distance = std::max(to_input.mean, from_input.mean);
  const bool angle_ok = after.smallest_angle_deg >= kMinAngleTarget, volume_ok = std::abs(volume_change) <= kVolumeTarget,
             distance_ok = mean_distance <= kDistanceTarget;
  out << "targets: smallest angle >= 20 deg " << (angle_ok ? "met" : "MISSED") << ", volume within 2 % "
      << (volume_ok ? "met" : "MISSED") << ", mean distance <= 1.5 mm " << (distance_ok ? "met" : "MISSED") << "\n";
  out << "wrote " << opt.out << " (" << after.nodes << " nodes, closed, outward, no self-intersection) in "
      << std::setprecision(3) << vdm::ms_since(t0) / 1000 << " s\n";
  return 0;
}

}  // namespace

int cmd_prepare_mesh(const PrepareMeshOptions& opt, std::ostream& out, std::ostream& err) {
  // CGAL reports what it cannot do with a surface by throwing (its checks and assertions):
  // that is bad input, not a crash.
  try {
    return prepare_mesh(opt, out, err);
  } catch (const std::exception& e) {
    err << "vdmsim: error: " << opt.in << ": the mesh library could not process this surface: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace vdmsim
