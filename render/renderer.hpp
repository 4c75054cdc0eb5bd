#pragma once
// The offscreen renderer: draws a RenderScene with OpenGL 4.5 core on OSMesa. The views
// (render/views.hpp): the pictures `shaded` (tissue material, key and fill lights, soft
// specular, floor shadow) and `stress` (the organ coloured by a quantity through a colour map
// with a fixed range), RGBA images, each with an optional ImGui HUD (scene, frame, time, force,
// fluid pressure, volume error, step time; a colour bar with units in the stress view),
// anti-aliased (RenderSettings::antialias); and the ground truth `depth`, `segmentation` and
// `normals`, from one exact pass (render/ground_truth_pass.hpp).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/types.hpp"
#include "render/camera.hpp"
#include "render/image.hpp"
#include "render/render_scene.hpp"
#include "render/view_image.hpp"
#include "render/view_settings.hpp"
#include "render/views.hpp"

namespace render {

// What drawing a view needs besides the scene.
struct ViewOptions {
  bool hud = true;     // picture views: the HUD
  StressView stress;   // the stress view's quantity, colours and range
};

class Renderer {
 public:
  // Creates the GL context and resources for the organ's fixed topology. nullptr + error on
  // failure (no OSMesa, shader compile error). `rest` must outlive the renderer: its
  // triangles are read (not copied) for each frame's normals.
  static std::unique_ptr<Renderer> create(const RenderSettings& settings, const vdm::SurfaceMesh& rest,
                                          std::string& error);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // One frame into `out`. False when OpenGL could not draw it (the organ's buffer could not
  // be mapped, a shader could not be built again, an OpenGL error was raised): `out` is then
  // not a picture of the scene, and error() says why. The next frame is drawn afresh.
  bool draw_shaded(const RenderScene& scene, bool hud, Image& out);
  bool draw_stress(const RenderScene& scene, const StressView& view, bool hud, Image& out);
  // Draws each of `views` of one frame in turn, handing each image (in its view's file format)
  // to `take` as soon as it is drawn; the image is reused for the next view. The ground-truth
  // views come from one pass, drawn once for the frame. False when a view could not be drawn
  // (error() says why; the views after it are not drawn); `take` returning false stops the
  // drawing too, which is not a failure of the renderer's.
  bool draw_views(const RenderScene& scene, const std::vector<View>& views, const ViewOptions& options,
                  const std::function<bool(View, ViewImage&)>& take);
  // Why the last frame could not be drawn (empty after a frame that was).
  const std::string& error() const;
  // Testing: the next frame's mapping of the organ's buffer fails as if OpenGL had refused it.
  void fail_next_map_for_testing();
  const Camera& camera() const;
  // The camera as a pinhole model (OpenCV's convention) with the planes it clips at.
  CameraModel camera_model() const;
  std::string gl_renderer() const;

  struct Impl;

 private:
  Renderer() = default;
  std::unique_ptr<Impl> impl_;
};

}  // namespace render
