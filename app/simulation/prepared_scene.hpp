#pragma once
// A scene made ready to simulate: the scene as loaded and validated, its organ's tissue model,
// the nodes its loads and motions act on, its instruments' skins and convex hulls, and the
// reference model of organ.model (organ_models.hpp; none for vdm).
#include <memory>
#include <string>
#include <vector>

#include "app/scene/scene.hpp"
#include "app/simulation/organ_models.hpp"
#include "app/simulation/surface_keyframes.hpp"
#include "engine/tissue_model.hpp"
#include "render/render_scene.hpp"

namespace vdmsim {

// Nodes of the rest mesh selected by `region` (sorted). Errors (a node index out of range, a
// region that selects nothing) are appended to `problems`, naming the region's position.
std::vector<int> select_nodes(const Region& region, const vdm::NodeMat& rest, const std::string& field,
                              std::vector<SceneProblem>& problems);

// An instrument's skin meshes, loaded and placed in the instrument frame (empty: parametric).
struct InstrumentSkin {
  std::shared_ptr<render::SkinMesh> body, jaws[2];
};

// One organ made ready: its tissue model (the surface placed, its holds), the nodes its loads and
// motions act on, and the reference model of its `model` (none for vdm).
struct PreparedOrgan {
  vdm::TissueModel model;
  std::vector<std::vector<int>> load_nodes;        // per loads entry
  std::vector<std::vector<int>> prescribed_nodes;  // per prescribed entry
  std::vector<vdm::Vec3> prescribed_about;         // rotation centre per entry (m)
  ReferenceModel reference;                        // the organ model's own (vdm: none, vdm::step)
};

struct PreparedScene {
  SceneDef scene;
  std::vector<PreparedOrgan> organs = std::vector<PreparedOrgan>(1);  // scene.organs' order
  // Every organ's rest surface as placed, in one mesh: organ i's nodes are node_offset[i] to
  // node_offset[i + 1] - 1 (the picture draws it; keyframes are placed on it).
  vdm::SurfaceMesh surface;
  std::vector<int> node_offset = {0, 0};
  std::vector<InstrumentSkin> skins;               // per instrument
  std::vector<SurfaceHit> surface_hits;            // per scene.surface_keyframes entry: where each landed

  // The first organ (the only one in the one-organ form).
  const PreparedOrgan& organ() const { return organs.front(); }
  PreparedOrgan& organ() { return organs.front(); }
};

// Loads and validates the scene and its mesh and builds the model. On failure returns false
// with every problem in `problems` (warnings are there too on success).
bool prepare_scene(const std::string& path, PreparedScene& out, std::vector<SceneProblem>& problems);
// The same from an already loaded (and possibly edited) scene.
// Places the scaled organ as organ.rotate_deg and organ.translate say: turned about the centre
// of its bounding box, about x, then y, then z (fixed axes), then moved.
void place_organ(vdm::NodeMat& x, const vdm::Vec3& rotate_deg, const vdm::Vec3& translate);
// Surfaces as one mesh: the nodes of each after those of the ones before it.
vdm::SurfaceMesh join_surfaces(const std::vector<vdm::SurfaceMesh>& parts);

bool prepare_scene_def(const SceneDef& scene, PreparedScene& out, std::vector<SceneProblem>& problems);

}  // namespace vdmsim
