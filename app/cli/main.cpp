// vdmsim: command-line entry point. Exit codes: 0 success, 2 bad input or usage (with a
// message naming the file or field), 1 runtime failure.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <unistd.h>

#include "app/studies/accuracy_command.hpp"
#include "app/studies/bench.hpp"
#include "app/cli/commands.hpp"
#include "app/cli/option_checks.hpp"
#include "app/compare/compare_command.hpp"
#include "app/mesh_prep/prepare_mesh.hpp"
#include "app/mesh_prep/ray_locate.hpp"
#include "app/run/program_version.hpp"
#include "app/scene/scene.hpp"
#include "app/scene/scene_reference.hpp"
#include "app/sweep/sweep_command.hpp"

namespace {
namespace cli = vdmsim::cli;
constexpr long long kMaxJobs = 100000;    // --jobs: processes at a time on one machine
constexpr long long kMaxArray = 1000000;  // --task, --max-parallel: a Slurm array's indices

// --frames: a whole number from 1 to kMaxFrames, or a message naming the bound.
CLI::Validator frame_count() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        long long n = 0;
        try {
          size_t used = 0;
          n = std::stoll(text, &used);
          if (used != text.size()) return "expected a whole number of frames, got '" + text + "'";
        } catch (const std::exception&) {
          return "expected a whole number of frames from 1 to " + std::to_string(vdmsim::kMaxFrames) + ", got '" + text + "'";
        }
        if (n < 1 || n > vdmsim::kMaxFrames)
          return text + " frames is out of range: from 1 to " + std::to_string(vdmsim::kMaxFrames) + " (10 million)";
        return "";
      },
      "1 to " + std::to_string(vdmsim::kMaxFrames));
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vdmsim: soft-tissue surgical simulation with the Volume Distribution Method"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("vdmsim ") + vdmsim::program_version());

  std::string mesh_path;
  double mesh_scale = 1.0;
  auto* mesh_info = app.add_subcommand("mesh-info", "Print a mesh's nodes, triangles, closedness, volume, area and bounding box");
  mesh_info->add_option("MESH", mesh_path, "Mesh file (OBJ, STL, PLY, glTF, ...)")->required();
  mesh_info->add_option("--scale", mesh_scale, "Multiply coordinates by this factor");

  vdmsim::PrepareMeshOptions prep_opt;
  auto* prepare_mesh = app.add_subcommand(
      "prepare-mesh",
      "Make a scanned surface an organ: repair, remesh, smooth; writes a closed outward OBJ in metres");
  prepare_mesh->add_option("IN", prep_opt.in, "The surface as segmented (OBJ, STL, PLY, ...; any units)")->required();
  prepare_mesh->add_option("--out", prep_opt.out, "Output OBJ (metres)")->required()->check(cli::named_path());
  prepare_mesh->add_option("--scale", prep_opt.scale, "Input units to metres (0.001 for millimetres)");
  auto* prep_nodes = prepare_mesh->add_option("--nodes", prep_opt.nodes, "Target node count (default 10000)")
                         ->check(cli::whole_number(100, vdmsim::kMaxPreparedNodes, "100 to 1000000"));
  prepare_mesh->add_option("--edge-length", prep_opt.edge_length, "Target edge length in metres (instead of --nodes)")
      ->check(cli::positive_number())
      ->excludes(prep_nodes);
  prepare_mesh->add_flag("--center", prep_opt.center, "Move the bounding box's centre to the origin");
  prepare_mesh->add_option("--iterations", prep_opt.iterations, "Isotropic remeshing passes (default 5)")
      ->check(CLI::Range(1, 50));
  prepare_mesh->add_option("--smoothing", prep_opt.smoothing,
                           "Smoothing strength: the time step of two mean-curvature-flow steps over the squared target "
                           "edge (default 0.1; 0: none); the volume is restored after");

  std::string locate_mesh;
  double locate_scale = 1.0;
  std::vector<double> locate_from, locate_toward;
  auto* locate = app.add_subcommand(
      "locate", "The first point of a mesh's surface along a ray, and its outward normal (to place instruments)");
  locate->add_option("MESH", locate_mesh, "Organ surface mesh (closed)")->required();
  locate->add_option("--scale", locate_scale, "Mesh units to metres (as the scene's organ.scale)");
  locate->add_option("--from", locate_from, "The ray's start X Y Z (m, after --scale)")->expected(3)->required();
  locate->add_option("--toward", locate_toward, "The ray's direction DX DY DZ (any length)")->expected(3)->required();

  std::string experiment, out_dir;
  auto* paper = app.add_subcommand("paper", "Reproduce an experiment of the VDM paper");
  paper->add_option("EXPERIMENT", experiment, "cube-stress | anisotropy | beam-stretch | beam-bend | beam-twist | all")->required();
  paper->add_option("--out", out_dir, "Output folder")->required()->check(cli::named_path());

  std::string organ = "liver", organ_out;
  int organ_level = 4;
  auto* make_organ = app.add_subcommand("make-organ", "Generate one of the project's organ meshes (OBJ, metres)");
  make_organ->add_option("ORGAN", organ, "Organ to generate: liver or gallbladder")->required();
  make_organ->add_option("--level", organ_level, "Subdivision level: 4, 5, 6 give 2562, 10242, 40962 nodes");
  make_organ->add_option("--out", organ_out, "Output OBJ file")->required()->check(cli::named_path());
  bool organ_scan_like = false;
  make_organ->add_flag("--scan-like", organ_scan_like,
                       "Damage it as a CT segmentation would (millimetres, scanner coordinates, bumpy, cropped open, "
                       "folded through itself): an input for prepare-mesh");

  std::string calib_mesh, calib_out;
  double calib_scale = 1.0, calib_young = 3000, calib_poisson = 0.45, calib_tet = 0;
  int calib_steps = 5;
  auto* calibrate = app.add_subcommand("calibrate", "Fit VDM's bulk and connectivity moduli to an FEM reference");
  calibrate->add_option("--mesh", calib_mesh, "Organ surface mesh (closed)")->required();
  calibrate->add_option("--scale", calib_scale, "Mesh units to metres");
  calibrate->add_option("--young", calib_young, "FEM Young's modulus (Pa)");
  calibrate->add_option("--poisson", calib_poisson, "FEM Poisson's ratio, [0, 0.5)");
  calibrate->add_option("--steps", calib_steps, "Steps of each load case");
  calibrate->add_option("--tet-size", calib_tet,
                        "Largest tet edge inside the organ (m; the surface's triangles are kept); 0: a tenth of the organ's smallest extent");
  calibrate->add_option("--out", calib_out, "Output YAML with the fitted material")->required()->check(cli::named_path());

  std::string scene_path;
  vdmsim::RunOptions run_opt;
  bool no_render = false;
  auto* run = app.add_subcommand("run", "Simulate and render a scene: PNG frames, metrics.csv, run.json");
  run->add_option("SCENE", scene_path, "Scene file (YAML)")->required();
  run->add_option("--out", run_opt.out_dir, "Output folder (default: out/<scene name>)")->check(cli::named_path());
  run->add_option("--frames", run_opt.frames, "Simulate only this many frames")->check(frame_count());
  run->add_flag("--no-render", no_render, "Do not render images (metrics.csv and run.json only)");
  run->add_flag("--video", run_opt.video, "Also write video.mp4 (H.264, needs the ffmpeg program)");
  run->add_flag("--export-mesh", run_opt.export_mesh,
                "Also write the organ's surface at every frame: DIR/mesh/frame_NNNNN.vtu (VTK XML, point data "
                "displacement and the stress view's quantities) and DIR/mesh.pvd (the time series, for ParaView)");
  run->add_flag("--resume", run_opt.resume, "Continue an interrupted run in --out DIR from its last checkpoint");
  run->add_option("--checkpoint-every", run_opt.checkpoint_every, "Frames between checkpoints (default 30)")
      ->check(cli::whole_number(1, vdmsim::kMaxFrames, "1 to 10000000"));
  std::string bench_out = "out/bench";
  bool bench_quick = false;
  std::string bench_only;
  auto* bench = app.add_subcommand("bench", "Performance cases: writes bench.csv and scaling.png");
  bench->add_option("--out", bench_out, "Output folder (default: out/bench)")->check(cli::named_path());
  bench->add_flag("--quick", bench_quick, "Fewer cases, frames and repeats (about 3 minutes)");
  bench->add_option("--only", bench_only, "Only the cases whose label contains this text (e.g. 'liver_probe 10k')");
  std::string bench_shared = "../shared/assets";
  bench->add_option("--shared-assets", bench_shared,
                    "Third-party data for the CT-like case (SOFA's scanned liver, organs/liver-smooth.obj; default "
                    "../shared/assets; the case is skipped without it)");
  int bench_case_fd = -1;  // internal: the process of one case writes its row there
  bench->add_option("--case-fd", bench_case_fd)->group("");
  vdmsim::AccuracyOptions accuracy_opt;
  auto* accuracy = app.add_subcommand("accuracy",
                                      "Accuracy against time: knobs swept on the liver probe and grasp scenes; "
                                      "writes accuracy.csv, accuracy.png, recommendations.md");
  accuracy->add_option("--out", accuracy_opt.out_dir, "Output folder (default: out/accuracy)")->check(cli::named_path());
  accuracy->add_flag("--quick", accuracy_opt.quick, "Coarser meshes, fewer knob values (under 2 minutes)");
  accuracy->add_flag("--ladder", accuracy_opt.ladder,
                     "The model ladder instead of the knobs: the paper's VDM, the membrane VDM, the elastic core and "
                     "the FEM against the converged FEM on the punch, the beams and the liver probe; writes ladder.csv, "
                     "ladder.png");
  accuracy->add_option("--scenario", accuracy_opt.scenario,
                       "Only this scenario: probe_poke or grasp_lift (default: both); with --ladder punch, beams or "
                       "liver_probe (default: all)");
  accuracy->add_option("--only", accuracy_opt.only,
                       "Only these knobs, comma-separated (solver, tolerance, refresh, nonlinear, mesh, capsule, model); "
                       "the reference and the baseline always run");
  accuracy->add_option("--jobs", accuracy_opt.jobs, "Configurations at a time on this machine (default: the number of cores)")
      ->check(cli::whole_number(1, kMaxJobs, "1 to 100000"));
  auto* accuracy_slurm = accuracy->add_flag(
      "--slurm", accuracy_opt.slurm, "Run the configurations as one Slurm job array (sbatch), wait for it, then measure");
  accuracy->add_option("--partition", accuracy_opt.partition, "--slurm: the partition to submit to (default: the cluster's)")
      ->needs(accuracy_slurm);
  accuracy->add_option("--max-parallel", accuracy_opt.max_parallel, "--slurm: array tasks running at a time (default: all)")
      ->check(cli::whole_number(1, kMaxArray, "1 to 1000000"))
      ->needs(accuracy_slurm);
  accuracy->add_option("--task", accuracy_opt.task,
                       "Run only configuration I (0-based; what each Slurm array task does), no report")
      ->check(cli::whole_number(0, kMaxArray, "0 to 1000000"))
      ->excludes(accuracy_slurm);
  vdmsim::SweepOptions sweep_opt;
  bool sweep_no_render = false;
  auto* sweep = app.add_subcommand("sweep",
                                   "Run a scene with values varied (a grid, lists together, or listed cases), on this "
                                   "machine or as a Slurm job array; writes DIR/runs/, summary.csv and summary.png");
  sweep->add_option("SWEEP", sweep_opt.sweep_file, "Sweep file (YAML): base: a scene; vary:, zip: or cases:")->required();
  sweep->add_option("--out", sweep_opt.out_dir, "Output folder: DIR/runs/<index>_<name>/ per run, DIR/summary.csv")
      ->required()
      ->check(cli::named_path());
  sweep->add_option("--jobs", sweep_opt.jobs, "Runs at a time on this machine (default: the number of cores)")
      ->check(cli::whole_number(1, kMaxJobs, "1 to 100000"));
  auto* sweep_slurm = sweep->add_flag("--slurm", sweep_opt.slurm,
                                      "Submit the runs as one Slurm job array (sbatch), wait for it, then summarise");
  sweep->add_option("--partition", sweep_opt.partition, "--slurm: the partition to submit to (default: the cluster's)")
      ->needs(sweep_slurm);
  sweep->add_option("--max-parallel", sweep_opt.max_parallel, "--slurm: array tasks running at a time (default: all)")
      ->check(cli::whole_number(1, kMaxArray, "1 to 1000000"))
      ->needs(sweep_slurm);
  sweep->add_option("--frames", sweep_opt.frames, "Simulate only this many frames of each run")->check(frame_count());
  sweep->add_flag("--no-render", sweep_no_render, "Do not render images (metrics.csv and run.json only; no summary.png)");
  sweep->add_flag("--video", sweep_opt.video, "Also write each run's video.mp4 (needs ffmpeg)");
  auto* sweep_task = sweep->add_option("--task", sweep_opt.task,
                                       "Run only run I (0-based; what each Slurm array task does), no summary")
                         ->check(cli::whole_number(0, kMaxArray, "0 to 1000000"));
  sweep_task->excludes(sweep_slurm);
  auto* check = app.add_subcommand("check", "Validate a scene and its mesh without simulating");
  check->add_option("SCENE", scene_path, "Scene file (YAML)")->required();
  std::string compare_expected, compare_actual;
  vdmsim::CompareOptions compare_opt;
  auto* compare = app.add_subcommand("compare",
                                     "Compare images with their expected versions (golden-image tests): two PNGs, or two "
                                     "run folders paired by file name; exit 0 within tolerance, 1 beyond it");
  compare->add_option("EXPECTED", compare_expected, "The expected PNG, or a folder of them (e.g. a run kept as reference)")
      ->required();
  compare->add_option("ACTUAL", compare_actual, "The PNG, or the folder of them (e.g. a run's output folder), to check")->required();
  compare->add_option("--max-diff", compare_opt.max_diff,
                      "Largest per-channel difference (0-255) a pixel may have and still match (default 0)")
      ->check(CLI::Range(0, 255));
  compare->add_option("--max-share", compare_opt.max_share,
                      "Share of pixels (0-1) allowed to differ by more than --max-diff (default 0)")
      ->check(CLI::Range(0.0, 1.0));
  compare->add_option("--diff", compare_opt.diff,
                      "Write the difference image to this PNG (two files), or one per pair into this folder (two folders)")
      ->check(cli::named_path());
  auto* scene_reference = app.add_subcommand(
      "scene-reference", "Print every scene key with its unit, default and range (docs/scene-reference.md, Markdown)");

  if (const std::string bad = cli::non_finite_number_argument(argc, argv); !bad.empty()) {
    std::cerr << "vdmsim: error: " << bad << "\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "vdmsim: " << e.what() << "\n" << "Run 'vdmsim --help' for usage.\n";
    return 2;
  }
  try {
    if (prepare_mesh->parsed()) return vdmsim::cmd_prepare_mesh(prep_opt, std::cout, std::cerr);
    if (locate->parsed())
      return vdmsim::cmd_locate(locate_mesh, locate_scale, vdm::Vec3(locate_from[0], locate_from[1], locate_from[2]),
                                vdm::Vec3(locate_toward[0], locate_toward[1], locate_toward[2]), std::cout, std::cerr);
    if (mesh_info->parsed()) return vdmsim::cmd_mesh_info(mesh_path, mesh_scale, std::cout, std::cerr);
    if (run->parsed()) {
      run_opt.render = !no_render;
      return vdmsim::cmd_run(scene_path, run_opt, std::cout, std::cerr, isatty(2) != 0);
    }
    if (bench->parsed()) return vdmsim::cmd_bench(bench_out, bench_quick, std::cout, std::cerr, bench_only, bench_case_fd,
                                                  bench_shared);
    if (accuracy->parsed()) return vdmsim::run_accuracy(accuracy_opt, std::cout, std::cerr, isatty(2) != 0);
    if (sweep->parsed()) {
      sweep_opt.render = !sweep_no_render;
      return vdmsim::cmd_sweep(sweep_opt, std::cout, std::cerr, isatty(2) != 0);
    }
    if (check->parsed()) return vdmsim::cmd_check(scene_path, std::cout, std::cerr);
    if (compare->parsed()) return vdmsim::cmd_compare(compare_expected, compare_actual, compare_opt, std::cout, std::cerr);
    if (scene_reference->parsed()) {
      vdmsim::write_scene_reference(std::cout);
      return 0;
    }
    if (make_organ->parsed()) return vdmsim::cmd_make_organ(organ, organ_level, organ_out, std::cout, std::cerr, organ_scan_like);
    if (calibrate->parsed())
      return vdmsim::cmd_calibrate(calib_mesh, calib_scale, calib_young, calib_poisson, calib_steps, calib_tet, calib_out,
                                   std::cout, std::cerr);
    if (paper->parsed()) return vdmsim::cmd_paper(experiment, out_dir, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "vdmsim: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
