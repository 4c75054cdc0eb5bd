#include "app/run/run_setup.hpp"

#include <yaml-cpp/yaml.h>

#include <sstream>
#include <utility>

#include "app/run/mesh_export.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/program_version.hpp"
#include "render/video.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;

void note_inert_instruments(const SceneDef& s, std::ostream& err) {
  bool has_probe = false, has_grasper = false;
  for (const InstrumentDef& in : s.instruments) (in.type == InstrumentDef::Type::probe ? has_probe : has_grasper) = true;
  if (has_probe && !s.has(Effect::contact))
    err << "vdmsim: note: the scene has probes but does not list the contact effect: they pass through the organ\n";
  if (has_grasper && !s.has(Effect::grasp))
    err << "vdmsim: note: the scene has graspers but does not list the grasp effect: they hold nothing\n";
}

}  // namespace

// Everything the run's result depends on (RunInputs): the scene file, the files it loads, the
// options and the program.
static RunInputs run_inputs(const SceneDef& s, const std::string& options) {
  RunInputs in;
  in.items.emplace_back("the scene file", file_hash(s.file));
  in.items.emplace_back("the organ mesh", file_hash(s.organ().mesh_path));
  for (size_t k = 0; k < s.instruments.size(); ++k) {
    const std::string which = "instrument " + std::to_string(k + 1) + "'s ";
    if (k < s.instrument_convex.size() && s.instrument_convex[k].present)
      in.items.emplace_back(which + "convex mesh", file_hash(s.instrument_convex[k].mesh));
    if (k < s.instrument_skins.size() && s.instrument_skins[k].present) {
      const SkinDef& skin = s.instrument_skins[k];
      if (!skin.body.empty()) in.items.emplace_back(which + "skin", file_hash(skin.body));
      for (int j = 0; j < 2; ++j)
        if (!skin.jaws[size_t(j)].empty())
          in.items.emplace_back(which + (j ? "lower" : "upper") + " jaw skin", file_hash(skin.jaws[size_t(j)]));
    }
  }
  in.items.emplace_back("the options", options);  // in words: shown as they were and are
  in.items.emplace_back("the vdmsim program", program_version());
  return in;
}

int run_frames(const SceneDef& s, const RunOptions& opt) { return opt.frames > 0 ? opt.frames : s.frames; }

bool run_renders(const SceneDef& s, const RunOptions& opt) {
  return opt.render && s.has_render && !s.render.views.empty();
}

RunInputs run_inputs(const SceneDef& s, const RunOptions& opt) {
  // The options that change results, in words without ';' or '=' (RunInputs). A resume must
  // export the mesh if and only if the interrupted run did: its frames' files would be
  // missing otherwise.
  std::ostringstream options;
  options << run_frames(s, opt) << " frames, " << (run_renders(s, opt) ? "rendered" : "not rendered")
          << (opt.export_mesh ? ", --export-mesh" : "");
  return run_inputs(s, options.str());
}

namespace {

// run.json's status and frame count ("" and -1 when it is not there or cannot be read).
std::pair<std::string, int> run_json_status(const fs::path& dir) {
  try {
    const YAML::Node js = YAML::LoadFile((dir / "run.json").string());
    const YAML::Node status = js["status"], frames = js["frames"];
    return {status && status.IsScalar() ? status.Scalar() : "", frames && frames.IsScalar() ? frames.as<int>(-1) : -1};
  } catch (const YAML::Exception&) {
    return {"", -1};
  }
}

// Without a checkpoint: a run that stopped before its first one, or no run at all.
int no_checkpoint(const RunSetup& setup, std::ostream& err) {
  std::error_code ec;
  const bool ran = fs::exists(setup.dir / "metrics.csv", ec) || fs::exists(setup.dir / "run.json", ec);
  err << "vdmsim: error: " << setup.checkpoint_path().string() << ": "
      << (ran ? "the run in " + setup.dir.string() +
                    " stopped before its first checkpoint (written every --checkpoint-every frames, 30 by "
                    "default): there is nothing to resume from; run it again without --resume"
              : "no run to resume in " + setup.dir.string() + " (no checkpoint.json): run it without --resume first")
      << "\n";
  return 2;
}

// The checkpoint's frame must be one of this run's, and a checkpoint at the last frame is of a
// completed run only when run.json says so: an edited or damaged checkpoint.json is refused.
int check_resume_frame(const RunSetup& setup, std::ostream& err) {
  const Checkpoint& cp = setup.resume_from;
  const std::string at = "vdmsim: error: " + setup.checkpoint_path().string() + ": ";
  if (cp.frames != setup.frames || cp.frame < 0 || cp.frame >= setup.frames) {
    err << at << "frame " << cp.frame << " of " << cp.frames << " frames does not fit this run's " << setup.frames
        << " frames (0 to " << setup.frames - 1 << "): damaged or edited; run it afresh without --resume\n";
    return 2;
  }
  if (cp.frame + 1 < setup.frames) return -1;
  const auto [status, frames] = run_json_status(setup.dir);
  if (status == "completed" && frames == setup.frames) return -1;
  err << at << "says every frame (to " << cp.frame << ") is done, but "
      << (status.empty() ? "there is no readable run.json"
                         : "run.json says status " + status + " with " + std::to_string(frames) + " frames")
      << ": they disagree (damaged or edited?); run it afresh without --resume\n";
  return 2;
}

// Resuming with --export-mesh: the frames before the resumed ones must be on disk, or the export
// would end with only the resumed frames.
int check_resumed_export(const RunSetup& setup, std::ostream& err) {
  const std::vector<int> missing = missing_export_frames(setup.dir, setup.start, setup.organs);
  if (missing.empty()) return -1;
  err << "vdmsim: error: " << (setup.dir / "mesh").string() << ": " << missing.size() << " of the " << setup.start
      << " frames this resume's --export-mesh extends are missing (frame " << missing.front()
      << (missing.size() > 1 ? " to " + std::to_string(missing.back()) : std::string())
      << "): run it afresh without --resume to export every frame\n";
  return 2;
}

// Resuming: the checkpoint must be of this run's inputs; when it is not, what changed is named.
int read_resume_point(RunSetup& setup, const RunOptions& opt, std::ostream& err) {
  std::string error;
  std::error_code ec;
  if (!fs::exists(setup.checkpoint_path(), ec)) return no_checkpoint(setup, err);
  if (!read_checkpoint(setup.checkpoint_path().string(), setup.resume_from, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  if (setup.resume_from.run_hash != setup.run_hash) {
    std::vector<std::string> changes = setup.inputs.changes_since(RunInputs::parse(setup.resume_from.inputs));
    if (changes.empty()) changes.push_back("the run's inputs");
    err << "vdmsim: error: " << setup.checkpoint_path().string() << ": cannot resume: since the interrupted run, ";
    for (size_t k = 0; k < changes.size(); ++k) err << (k ? "; " : "") << changes[k];
    err << " (run it afresh without --resume)\n";
    return 2;
  }
  if (const int code = check_resume_frame(setup, err); code >= 0) return code;
  setup.start = setup.resume_from.frame + 1;
  if (opt.export_mesh)
    if (const int code = check_resumed_export(setup, err); code >= 0) return code;
  if (setup.start >= setup.frames) {
    err << "vdmsim: note: " << setup.dir.string() << ": the run was already complete (" << setup.frames
        << " frames): nothing to do\n";
    return 0;
  }
  return -1;
}

// A fresh run: outputs of an earlier run in this folder would be stale.
void remove_earlier_outputs(const fs::path& dir) {
  std::error_code ec;
  // run.json first: a fresh run killed before it writes its own leaves no other run's summary
  // beside its frames.
  for (const char* old : {"run.json", "checkpoint.json", "state.bin", "contact_sheet.png", "ffmpeg.log", "camera.json",
                          "poses.csv", "video.mp4"})
    fs::remove(dir / old, ec);
  for (const render::ViewRow& row : render::view_table())  // the picture views' videos (render::video_file_name)
    if (row.pass == render::ViewPass::picture) fs::remove(dir / (std::string(row.name) + ".mp4"), ec);
}

}  // namespace

int set_up_run(const PreparedScene& ps, const RunOptions& opt, RunSetup& setup, std::ostream& err) {
  const SceneDef& s = ps.scene;
  setup.frames = run_frames(s, opt);
  setup.organs = organ_names(ps);
  setup.dir = opt.out_dir.empty() ? fs::path("out") / safe_folder_name(s.name) : fs::path(opt.out_dir);
  setup.rendering = run_renders(s, opt);
  setup.resume = opt.resume;
  if (opt.video && !setup.rendering) {
    err << "vdmsim: error: --video needs rendered frames: " << (opt.render ? s.file + " has no render: section" : "drop --no-render")
        << "\n";
    return 2;
  }
  if (opt.video && !s.render.has_picture()) {
    err << "vdmsim: error: --video needs a picture view (shaded or stress) in " << s.file
        << "'s render.views: the ground-truth views are not made into videos\n";
    return 2;
  }
  // Checked before anything is simulated: ffmpeg reads the frames through a pattern
  // (DIR/frames/frame_%05d.png), in which a '%' of the folder's name would be taken for another
  // number and the video would fail only after every frame was rendered.
  if (opt.video && setup.dir.string().find('%') != std::string::npos) {
    err << "vdmsim: error: --out " << setup.dir.string()
        << ": with --video the output folder's path may not contain '%' (ffmpeg reads the frames through a "
           "%-pattern): choose another folder\n";
    return 2;
  }
  if (opt.video && render::find_program("ffmpeg").empty()) {
    err << "vdmsim: error: --video needs the ffmpeg program, which is not installed (apt-get install ffmpeg)\n";
    return 1;
  }
  std::string error;
  bool at_run_time = false;
  if (!prepare_output_dir(setup.dir.string(), error, &at_run_time)) {
    err << "vdmsim: error: " << error << "\n";
    return at_run_time ? 1 : 2;
  }
  setup.lock = std::make_shared<OutputLock>();
  if (!setup.lock->acquire(setup.dir, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  note_inert_instruments(s, err);
  setup.inputs = run_inputs(s, opt);
  setup.run_hash = setup.inputs.hash();
  if (opt.resume) return read_resume_point(setup, opt, err);
  remove_earlier_outputs(setup.dir);
  remove_mesh_export(setup.dir, setup.organs);
  return -1;
}

}  // namespace vdmsim
