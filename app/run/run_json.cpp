#include "app/run/run_json.hpp"

#include "app/run/json_text.hpp"
#include "app/simulation/organ_models.hpp"
#include "engine/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace vdmsim {
namespace {

// The contact's method and how its solves went: the linear-solver iterations of every contact
// solve, and the steps whose active set was still changing when the iteration cap was reached.
void write_contact(const RunRecord& r, std::ostream& js) {
  const SceneDef& s = r.prepared.scene;
  using Method = vdm::ContactSettings::Method;
  const Method method = s.contact.method;
  const bool constraint = method == Method::constraint;
  const char* name = method == Method::penalty ? "penalty" : constraint ? "constraint" : "kinematic";
  js << "  \"contact\": {\"method\": \"" << name << '"';
  if (method == Method::penalty) js << ", \"stiffness_pa_per_m\": " << s.contact.penalty_stiffness;
  if (constraint) js << ", \"friction\": " << s.contact.friction;
  js << ", \"iterations\": " << r.contact_iterations << ", \"unconverged_steps\": " << r.unconverged_contact_steps;
  js << "},\n";
}

// Per instrument, in the scene's order: its type and the largest force of the organ on it.
void write_instruments(const RunRecord& r, std::ostream& js) {
  const SceneDef& s = r.prepared.scene;
  js << "  \"instruments\": [";
  for (size_t k = 0; k < s.instruments.size(); ++k) {
    const bool probe = s.instruments[k].type == tools::InstrumentDef::Type::probe;
    js << (k ? ", " : "") << "{\"type\": \"" << (probe ? "probe" : "grasper") << "\", \"peak_force_n\": ";
    if (r.forces && k < r.peak_forces.size()) js << r.peak_forces[k];
    else js << "null";
    js << '}';
  }
  js << "],\n";
}

void write_times(const RunRecord& r, std::ostream& js) {
  const RunTally& t = r.tally;
  const StageTimes& st = r.stage_times;
  js << "  \"wall_time_s\": " << r.wall_s << ",\n  \"mean_step_ms\": "
     << (t.step_ms.empty() ? 0.0 : t.sum_step / double(t.step_ms.size()))
     << ",\n  \"median_step_ms\": " << t.median_step() << ",\n  \"max_step_ms\": " << t.max_step
     << ",\n  \"max_volume_rel_error\": " << t.max_volume_error << ",\n  \"stage_ms\": {\"loads\": " << st.loads
     << ", \"assemble\": " << st.assemble << ", \"solve\": " << st.solve << ", \"stress\": " << st.stress
     << ", \"grasp\": " << st.grasp << ", \"collision\": " << st.collision << ", \"metrics_io\": " << t.io_ms;
  if (r.mesh && r.mesh->active()) js << ", \"mesh_export\": " << r.mesh->write_ms();
  if (r.setup.rendering)
    js << ", \"colour_range_pass\": " << r.colour_range_ms << ", \"render\": " << r.output.render_ms()
       << ", \"png_encode\": " << r.output.encode_ms();
  js << "},\n  \"collision_queries\": " << st.collision_queries << ",\n";
}

void write_render(const RunRecord& r, std::ostream& js) {
  if (!r.setup.rendering) {
    js << "  \"render\": null,\n";
    return;
  }
  const RenderDef& rd = r.prepared.scene.render;
  const render::StressView& view = r.output.stress_view();
  js << "  \"render\": {\"width\": " << rd.settings.width << ", \"height\": " << rd.settings.height
     << ", \"antialias\": \"" << render::to_string(rd.settings.antialias) << "\", \"samples\": "
     << rd.settings.msaa_samples() << ", \"views\": [";
  for (size_t i = 0; i < rd.views.size(); ++i) js << (i ? ", " : "") << '"' << render::view_row(rd.views[i]).name << '"';
  js << "], \"images_written\": " << r.output.images_written();
  if (rd.has(render::View::stress))
    js << ", \"stress_quantity\": \"" << render::to_string(view.quantity) << "\", \"stress_range\": [" << view.lo << ", "
       << view.hi << "], \"stress_range_source\": \"" << (rd.range_auto ? "first pass" : "scene") << "\"";
  // The segmentation view's ids (render/views.hpp): the organ's, then each instrument's.
  if (rd.has(render::View::segmentation)) {
    const std::vector<OrganDef>& organs = r.prepared.scene.organs;
    const int n = static_cast<int>(organs.size());
    js << ", \"segmentation_ids\": {";
    if (n == 1) js << "\"organ\": " << render::kOrganId;
    for (int i = 0; n > 1 && i < n; ++i)
      js << (i ? ", " : "") << '"' << json_escape(organs[static_cast<size_t>(i)].name) << "\": " << render::organ_id(i);
    for (size_t k = 0; k < r.prepared.scene.instruments.size(); ++k)
      js << ", \"instruments[" << k << "]\": " << render::instrument_id(int(k), n);
    js << '}';
  }
  js << ", \"video\": \"" << json_escape(r.video_status) << "\"},\n";
}

// What --export-mesh wrote (null when not asked): the frames mesh.pvd lists, its point data,
// and why the stress quantities are missing when they are.
void write_mesh_export(const RunRecord& r, std::ostream& js) {
  if (!r.mesh || !r.mesh->active()) {
    js << "  \"mesh_export\": null,\n";
    return;
  }
  js << "  \"mesh_export\": {\"frames\": " << r.mesh->frames() << ", \"pvd\": \"mesh.pvd\", \"point_data\": [";
  const std::vector<std::string> names = r.mesh->point_data();
  for (size_t i = 0; i < names.size(); ++i) js << (i ? ", " : "") << '"' << names[i] << '"';
  js << ']';
  if (!r.mesh->omitted_reason().empty())
    js << ", \"stress_quantities\": \"not exported: " << json_escape(r.mesh->omitted_reason()) << '"';
  js << "},\n";
}

// Each organ: its name, nodes, model (and material), and its largest volume error.
void write_organs(const RunRecord& r, std::ostream& js) {
  const SceneDef& s = r.prepared.scene;
  js << "  \"organs\": [";
  for (size_t i = 0; i < s.organs.size(); ++i) {
    const OrganDef& o = s.organs[i];
    const PreparedOrgan& po = r.prepared.organs[i];
    js << (i ? ",\n    " : "\n    ") << "{\"name\": \"" << json_escape(o.name) << "\", \"nodes\": " << po.model.n
       << ", \"model\": \"" << vdm::to_string(o.model) << '"';
    std::ostringstream material;
    material << std::setprecision(9);
    organ_model_run(o.model).write_run_json(o, po, material);
    if (!material.str().empty()) js << ", " << material.str();
    if (i < r.organ_max_volume_errors.size()) js << ", \"max_volume_rel_error\": " << r.organ_max_volume_errors[i];
    js << '}';
  }
  js << "\n  ],\n";
}

}  // namespace

std::string run_json(const RunRecord& r) {
  const SceneDef& s = r.prepared.scene;
  const vdm::TissueModel& m = r.prepared.organ().model;
  std::ostringstream js;
  js << std::setprecision(9);
  js << "{\n  \"scene\": \"" << json_escape(s.name) << "\",\n  \"scene_file\": \"" << json_escape(s.file)
     << "\",\n  \"status\": \"" << r.outcome.status << "\",\n";
  if (!r.outcome.reason.empty()) js << "  \"reason\": \"" << json_escape(r.outcome.reason) << "\",\n";
  if (r.setup.resume)
    js << "  \"resumed_from_frame\": " << r.setup.start << ",\n  \"resumed_by\": \""
       << (r.resumed_by_snapshot ? "state snapshot" : "re-simulation") << "\",\n";
  js << "  \"frames\": " << r.outcome.done << ",\n  \"frames_requested\": " << r.setup.frames << ",\n  \"nodes\": "
     << r.prepared.surface.node_count();
  // One organ: its model and material at the top (as every run.json has them); several: in organs.
  if (r.prepared.organs.size() == 1) js << ",\n  \"model\": \"" << vdm::to_string(s.organ().model) << '"';
  js << ",\n  \"solver\": \"" << vdm::to_string(m.solver.method) << "\",\n  \"effects\": [";
  for (size_t i = 0; i < s.effects.size(); ++i) js << (i ? ", " : "") << '"' << to_string(s.effects[i]) << '"';
  js << "],\n";
  if (r.prepared.organs.size() == 1) {
    std::ostringstream material;
    material << std::setprecision(9);
    organ_model_run(s.organ().model).write_run_json(s.organ(), r.prepared.organ(), material);
    if (!material.str().empty()) js << "  " << material.str() << ",\n";
  }
  write_organs(r, js);
  if (s.has(Effect::contact)) write_contact(r, js);
  write_instruments(r, js);
  write_times(r, js);
  write_render(r, js);
  write_mesh_export(r, js);
  js << "  \"warnings\": [";
  for (size_t i = 0; i < r.warnings.size(); ++i) js << (i ? ", " : "") << '"' << json_escape(r.warnings[i]) << '"';
  js << "]\n}\n";
  return js.str();
}

}  // namespace vdmsim
