#pragma once
// What a scene asks of its pictures: the image size, anti-aliasing, camera, floor and shadows
// (RenderSettings), and how the stress view colours the organ (StressView). Plain settings,
// so that the scene's reader and the HUD need not include the renderer.
#include <vector>

#include "render/camera.hpp"
#include "render/colormap.hpp"
#include "render/render_scene.hpp"
#include "tools_scripted/endoscope.hpp"

namespace render {

// How edges are anti-aliased: `edge` draws one sample per pixel and smooths the edges'
// staircases on the CPU (render/edge_aa.hpp; the HUD is drawn after it, untouched), `msaa`
// multisamples with `samples` per pixel (llvmpipe's multisampling costs about twice the
// single-sample drawing, plus the resolve), `none` draws one sample per pixel as it is.
enum class Antialias { none, edge, msaa };

const char* to_string(Antialias a);  // "edge", "msaa", "none"

// What the automatic camera frames: the organ's rest bounding box, or the instruments'
// working area (a box the scene's side computes: RenderSettings::focus_lo, focus_hi).
enum class CameraFocus { organ, instruments };
const char* to_string(CameraFocus f);  // "organ", "instruments"

// The camera: a framing camera outside the body (look-at, fixed for the sequence), or an
// endoscope through a port (its pose each frame in RenderScene::camera_pose; its light at its
// tip; the abdomen's wall behind the organ instead of the floor).
enum class CameraType { framing, endoscope };
const char* to_string(CameraType t);  // "framing", "endoscope"

// How an organ's tissue looks in the shaded views (the stress view colours every organ by its
// quantity).
enum class TissueLook { liver, gallbladder };

// A part of the drawn surface: `triangles` triangles (the surface's next ones, in order) that
// look as `look`.
struct OrganPart {
  long triangles = 0;
  TissueLook look = TissueLook::liver;
};

struct RenderSettings {
  int width = 1280, height = 720;
  Antialias antialias = Antialias::edge;
  int samples = 4;           // MSAA samples per pixel, used when antialias == msaa
  int msaa_samples() const { return antialias == Antialias::msaa ? samples : 1; }
  bool auto_camera = true;   // frame the organ's rest bounding box (or the focus box)
  CameraFocus focus = CameraFocus::organ;
  bool has_focus_box = false;               // auto_camera frames [focus_lo, focus_hi] instead
  Eigen::Vector3d focus_lo = Eigen::Vector3d::Zero(), focus_hi = Eigen::Vector3d::Zero();  // m
  Camera camera;             // used when !auto_camera
  CameraType camera_type = CameraType::framing;
  tools::EndoscopeDef endoscope;  // camera_type endoscope: its port, aim, optics and script
  // Other ports in the abdominal wall (the instruments'): the wall drawn behind the organ
  // passes through or inside each of them and the endoscope's, so that no shaft is seen
  // outside the abdomen.
  std::vector<Eigen::Vector3d> ports;
  bool gizmo = false;        // small x, y, z axes in the bottom-left corner
  bool floor = true;         // a floor under the organ, with the key light's shadow
  bool shadows = true;
  // The surface's organs in order (several organs: each in its look, with its own
  // segmentation id); empty: all of it one organ, liver.
  std::vector<OrganPart> organ_parts;
};

struct StressView {
  Quantity quantity = Quantity::stress_magnitude;
  ColorMapName colormap = ColorMapName::viridis;
  double lo = 0, hi = 1;  // colour range, fixed across a sequence
};

}  // namespace render
