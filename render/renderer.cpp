#include "render/renderer.hpp"

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cstdint>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <tuple>

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "render/abdomen.hpp"
#include "render/edge_aa.hpp"
#include "render/gl_context.hpp"
#include "render/gl_program.hpp"
#include "render/gizmo.hpp"
#include "render/ground_truth_pass.hpp"
#include "render/hud.hpp"
#include "render/imgui_layer.hpp"
#include "render/instrument_geometry.hpp"
#include "render/shaders.hpp"
#include "render/tissue_texture.hpp"

namespace render {
namespace {

// A static triangle mesh on the GPU: position and normal per vertex.
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei count = 0;
  Eigen::AlignedBox3f box;  // of the vertices, in the mesh's frame: what its shadow can reach
  void upload(const SkinMesh& m) {
    box.setEmpty();
    for (const Eigen::Vector3f& p : m.positions) box.extend(p);
    std::vector<float> data;
    data.reserve(m.positions.size() * 6);
    for (size_t i = 0; i < m.positions.size(); ++i) {
      data.insert(data.end(), {m.positions[i].x(), m.positions[i].y(), m.positions[i].z()});
      data.insert(data.end(), {m.normals[i].x(), m.normals[i].y(), m.normals[i].z()});
    }
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ebo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.indices.size() * sizeof(unsigned)), m.indices.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
    glDisableVertexAttribArray(2);
    glVertexAttrib1f(2, 0.0f);
    glDisableVertexAttribArray(3);
    glVertexAttrib3f(3, 0.0f, 0.0f, 0.0f);
    glBindVertexArray(0);
    count = GLsizei(m.indices.size());
  }
  void destroy() {
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ebo);
  }
  void draw() const {
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
  }
};

// An instrument's parametric meshes: its body (a probe, or a grasper's or hook's shaft), a
// grasper's jaws, a hook's wire.
struct InstrumentMeshes {
  GpuMesh body, jaws[2], wire;
};
// Which parts of the instruments a draw takes: the endoscope's view draws the shafts' black
// insulation and the bare metal (jaws, a hook's wire) in two colours.
enum class InstrumentParts { all, shafts, metal };

Eigen::Vector3f f3(const Eigen::Vector3d& v) { return v.cast<float>(); }

// A capsule probe drawn as a hook (other shapes are drawn as they collide).
bool hook_look(const InstrumentView& v) {
  return v.probe_look == tools::InstrumentDef::ProbeLook::hook && v.shape.kind == tools::ProbeShape::Kind::capsule;
}

// The endoscope's near clip plane (m): its tip can come this close to the tissue.
constexpr double kEndoscopeNear = 0.001;
// The tissue texture's coarse scale: one period of its field over this much of the rest shape.
constexpr double kTissueTexturePeriod = 0.05;  // m

// VDMSIM_RENDER_TIMING=1 prints the wall and CPU time (all of the process's threads,
// llvmpipe's included) of each pass, with glFinish between passes, so the total is slower
// than a normal frame: for profiling only.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}
struct PassTimer {
  bool on = std::getenv("VDMSIM_RENDER_TIMING") != nullptr;
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  double cpu0 = on ? process_cpu_ms() : 0.0;
  void mark(const char* what) {
    if (!on) return;
    glFinish();
    const auto t = std::chrono::steady_clock::now();
    const double cpu = process_cpu_ms();
    std::fprintf(stderr, "render %-12s %7.2f ms  cpu %7.2f ms\n", what,
                 std::chrono::duration<double, std::milli>(t - t0).count(), cpu - cpu0);
    t0 = t;
    cpu0 = cpu;
  }
};

}  // namespace

struct Renderer::Impl {
  enum Material { kTissue, kColormap, kMetal, kWall };  // kWall: the endoscope's only
  RenderSettings settings;
  std::unique_ptr<GlContext> gl;
  std::unique_ptr<Framebuffer> fb;
  GlProgram materials[4], mask_program, floor_program, background;
  GpuMesh floor;
  GLuint empty_vao = 0;
  // The organ: topology fixed, positions, normals and the scalar streamed each frame.
  GLuint organ_vao = 0, organ_vbo = 0, organ_ebo = 0;
  GLuint organ_rest_vbo = 0;  // the rest positions: the tissue texture's coordinates
  GLsizei organ_count = 0;
  const vdm::TriMat* triangles = nullptr;  // the rest mesh's (Renderer::create: it outlives the renderer)
  std::vector<Eigen::Vector3f> normals;
  // Instruments (parametric, by dimensions) and skins (by address).
  std::map<std::tuple<int, int, int, double, double, double, int, double, double, double, double, const void*>, InstrumentMeshes>
      instruments;
  std::map<const SkinMesh*, GpuMesh> skins;
  // The floor's shadow mask.
  GLuint mask_fbo = 0, mask_tex = 0;
  static constexpr int kMaskSize = 512;  // coarse on purpose: bilinear lookups give a soft edge
  double mask_half = 1;
  // The part of the floor where the mask can darken it this frame (floor coordinates
  // x0, y0, x1, y1); the rest of the floor is the backdrop's.
  Eigen::Vector4f shadow_rect = Eigen::Vector4f::Zero();
  GpuMesh shadow_quad;
  // The backdrop: the background gradient and the unshadowed floor, fixed for the renderer's
  // camera, drawn once and copied into each frame (a copy of the multisampled colour costs
  // far less than shading the floor and the background again).
  GLuint backdrop_fbo = 0, backdrop_color = 0;
  std::map<ColorMapName, GLuint> colormaps;
  // antialias: edge: the edge smoother, and the HUD's own layer (premultiplied RGBA, drawn
  // after the smoothing and composited over the frame).
  EdgeSmoother smoother;
  Image hud_layer;
  ImGuiLayer imgui;
  Camera camera;
  // The endoscope: its light's exposure distance this frame, the abdomen's wall, the tissue's
  // texture, and each node's depth in a crease (its shading) with what it is computed from.
  bool endoscope = false;
  double light_distance = 0.1;
  Abdomen abdomen;
  GpuMesh wall;
  GLuint noise_tex = 0;
  std::vector<float> crease, node_crease;
  std::vector<double> seen_depths;
  std::vector<Eigen::Vector3f> neighbour_sum;
  std::vector<float> neighbour_count, edge_sum;
  Eigen::Vector3d centre, lo, hi;
  double radius = 1, floor_z = 0;
  Eigen::Vector3d key_dir = Eigen::Vector3d(-0.55, -0.65, 1.2).normalized();
  Eigen::Vector3d fill_dir = Eigen::Vector3d(0.9, -0.3, 0.25).normalized();
  Eigen::Matrix4f view_proj = Eigen::Matrix4f::Identity(), floor_proj = Eigen::Matrix4f::Identity();
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();  // world -> OpenGL's camera space
  double near_plane = 0, far_plane = 0;                 // the projection's clip planes (m)
  // The ground-truth views' pass, made by the first frame that needs it.
  std::unique_ptr<GroundTruthPass> ground_truth;
  ViewImage view_image;  // draw_views' image, reused frame to frame
  std::vector<Eigen::Vector4f> capsule_a, capsule_b;
  std::vector<Eigen::Vector4f> box_centre, box_half;  // box and convex probes' shadows
  std::vector<Eigen::Matrix3f> box_axes;

  ~Impl() {
    if (!gl) return;
    gl->make_current();
    for (auto& [key, m] : instruments) {
      m.body.destroy();
      m.jaws[0].destroy();
      m.jaws[1].destroy();
    }
    for (auto& [key, m] : skins) m.destroy();
    floor.destroy();
    shadow_quad.destroy();
    if (endoscope) wall.destroy();
    glDeleteTextures(1, &noise_tex);
    glDeleteBuffers(1, &organ_rest_vbo);
    glDeleteFramebuffers(1, &backdrop_fbo);
    glDeleteRenderbuffers(1, &backdrop_color);
    glDeleteVertexArrays(1, &organ_vao);
    glDeleteBuffers(1, &organ_vbo);
    glDeleteBuffers(1, &organ_ebo);
    glDeleteVertexArrays(1, &empty_vao);
    glDeleteFramebuffers(1, &mask_fbo);
    glDeleteTextures(1, &mask_tex);
    for (auto& [name, tex] : colormaps) glDeleteTextures(1, &tex);
    ground_truth.reset();
    fb.reset();
  }

  bool init(const vdm::SurfaceMesh& rest, std::string& error);
  void upload_positions(const vdm::NodeMat& x);
  void upload_normals(const vdm::NodeMat& x, const std::vector<float>* scalar, GLsync mask_done);
  void find_creases(const vdm::NodeMat& x);
  void set_camera(const RenderScene& scene);
  double exposure_distance(const RenderScene& scene);
  void set_tissue(GlProgram& p, const Eigen::Vector3f& base, const Eigen::Vector3f& second, float bump, double period,
                  bool world);
  InstrumentMeshes& instrument_meshes(const InstrumentView& v);
  GpuMesh& skin_mesh(const SkinMesh* s);
  GLuint colormap_texture(ColorMapName name);
  // `id_uniform` (the ground-truth pass): set to each instrument's segmentation id, when >= 0.
  void draw_instruments(const RenderScene& scene, GlProgram& prog, bool mask_only, int id_uniform = -1,
                        InstrumentParts parts = InstrumentParts::all);
  void set_capsules(const RenderScene& scene);
  void shadow_mask_pass(const RenderScene& scene);
  void find_shadow_rect(const RenderScene& scene);
  void draw_floor(const GpuMesh& quad, bool shadowed);
  void draw_background();
  bool build_material(Material m, std::string& error);
  bool make_backdrop(std::string& error);
  void set_view_proj();
  GlProgram& use(Material m);
  void draw_hud_layer(const RenderScene& scene, const StressView* view, bool hud, Image& out);
  void draw_overlay(const RenderScene& scene, const StressView* view, bool hud);
  void draw_frame(const RenderScene& scene, const StressView* view, bool hud, Image& out);
  bool draw(const RenderScene& scene, const StressView* view, bool hud, Image& out);
  bool draw_ground_truth(const RenderScene& scene);
  void draw_ground_truth_pass(const RenderScene& scene);
  // Draws the bound organ surface part by part (settings.organ_parts; none: the whole surface
  // as one liver), calling before_part(i, look) ahead of part i's draw call.
  template <typename BeforePart>
  void draw_organ_parts(const BeforePart& before_part);
  template <typename DrawFrame>
  bool guarded(const DrawFrame& draw_frame);
  float* map_organ_buffer();

  std::string frame_error;  // why the frame being drawn failed (the first reason)
  bool fail_next_map = false;
};

bool Renderer::Impl::init(const vdm::SurfaceMesh& rest, std::string& error) {
  gl = GlContext::create(error);
  if (!gl) return false;
  fb = std::make_unique<Framebuffer>(settings.width, settings.height, settings.msaa_samples());
  if (!fb->ok()) {
    error = "OpenGL framebuffer incomplete at " + std::to_string(settings.width) + "x" + std::to_string(settings.height);
    return false;
  }
  for (int k = 0; k < (endoscope ? 4 : 3); ++k)
    if (!build_material(Material(k), error)) return false;
  // The colour-map material (stress views) is checked here and built again by its first use:
  // each linked program keeps about 1 MB of driver memory, for nothing in a shaded-only run.
  materials[kColormap].reset();
  if (!mask_program.build(shaders::kShadowMaskVertex, shaders::kShadowMaskFragment, error) ||
      !floor_program.build(shaders::kMeshVertex, shaders::kFloorFragment, error) ||
      !background.build(shaders::kBackgroundVertex, shaders::kBackgroundFragment, error))
    return false;
  glGenVertexArrays(1, &empty_vao);

  // Organ buffers: positions, normals and the scalar per node, topology fixed.
  triangles = &rest.triangles;
  const Eigen::Index n = rest.positions.rows();
  normals.resize(static_cast<size_t>(n));
  glGenVertexArrays(1, &organ_vao);
  glGenBuffers(1, &organ_vbo);
  glGenBuffers(1, &organ_ebo);
  glBindVertexArray(organ_vao);
  glBindBuffer(GL_ARRAY_BUFFER, organ_vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(normals.size() * 7 * sizeof(float)), nullptr, GL_STREAM_DRAW);
  std::vector<unsigned> idx(static_cast<size_t>(triangles->size()));
  for (Eigen::Index i = 0; i < triangles->size(); ++i) idx[static_cast<size_t>(i)] = unsigned(triangles->data()[i]);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, organ_ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(idx.size() * sizeof(unsigned)), idx.data(), GL_STATIC_DRAW);
  organ_count = GLsizei(idx.size());
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, 7 * sizeof(float), reinterpret_cast<void*>(6 * sizeof(float)));
  std::vector<float> rest_xyz(static_cast<size_t>(3 * n));
  for (Eigen::Index i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) rest_xyz[static_cast<size_t>(3 * i + d)] = float(rest.positions(i, d));
  glGenBuffers(1, &organ_rest_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, organ_rest_vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(rest_xyz.size() * sizeof(float)), rest_xyz.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(3);
  glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindVertexArray(0);

  // Framing from the rest shape.
  lo = rest.positions.colwise().minCoeff().transpose();
  hi = rest.positions.colwise().maxCoeff().transpose();
  centre = 0.5 * (lo + hi);
  radius = std::max(0.5 * (hi - lo).norm(), 1e-6);
  floor_z = lo.z() - 0.02 * radius;
  const double aspect = double(settings.width) / settings.height;
  if (endoscope) {
    std::vector<Eigen::Vector3d> ports = settings.ports;
    ports.push_back(settings.endoscope.port);
    abdomen = abdomen_around(lo, hi, ports);
    wall.upload(abdomen_wall(abdomen, 48));
    // 32^3 texels (128 KB, within a core's cache; the finest octave two texels a cell): at
    // 64^3 (1 MB) the fine bumps' fetch missed the cache and the endoscope's frame took about
    // 6 % longer, for a grain barely finer.
    const int texels = 32;
    const std::vector<std::uint8_t> noise = tissue_noise_texture(texels, 20261202u);
    glGenTextures(1, &noise_tex);
    glBindTexture(GL_TEXTURE_3D, noise_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8, texels, texels, texels, 0, GL_RGBA, GL_UNSIGNED_BYTE, noise.data());
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTexParameteri(GL_TEXTURE_3D, wrap, GL_REPEAT);
    RenderScene first;
    const tools::EndoscopePose pose = tools::endoscope_at(settings.endoscope, 0.0);
    first.camera_pose = pose.camera;
    first.light_distance = (pose.look_at - pose.tip).norm();
    set_camera(first);
  } else if (!settings.auto_camera) camera = settings.camera;
  else if (settings.has_focus_box) camera = auto_frame(settings.focus_lo, settings.focus_hi, settings.camera.fov_deg, aspect);
  else camera = auto_frame(lo, hi, settings.camera.fov_deg, aspect);

  // The floor's shadow mask: a square of the floor around the organ, seen along the key
  // light.
  mask_half = 1.6 * radius;
  glGenTextures(1, &mask_tex);
  glBindTexture(GL_TEXTURE_2D, mask_tex);
  glTexStorage2D(GL_TEXTURE_2D, 4, GL_R8, kMaskSize, kMaskSize);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glGenFramebuffers(1, &mask_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, mask_fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, mask_tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    error = "OpenGL shadow-mask framebuffer incomplete";
    return false;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // World -> along the key light onto the plane z = floor_z -> the mask's square.
  // (GLM, column-major: m[column][row].)
  glm::dmat4 along(1.0);
  along[2][0] = -key_dir.x() / key_dir.z();
  along[2][1] = -key_dir.y() / key_dir.z();
  along[3][0] = key_dir.x() / key_dir.z() * floor_z;
  along[3][1] = key_dir.y() / key_dir.z() * floor_z;
  along[2][2] = 0;
  glm::dmat4 to_mask(1.0);
  to_mask[0][0] = to_mask[1][1] = 1.0 / mask_half;
  to_mask[3][0] = -centre.x() / mask_half;
  to_mask[3][1] = -centre.y() / mask_half;
  const glm::mat4 projection(to_mask * along);
  std::memcpy(floor_proj.data(), glm::value_ptr(projection), sizeof(float) * 16);

  // The floor: a square of half side 3 R under the organ (it has faded out at its edge).
  SkinMesh square;
  const float fr = float(3 * radius), cx = float(centre.x()), cy = float(centre.y()), fz = float(floor_z);
  for (int k = 0; k < 4; ++k) {
    square.positions.emplace_back(cx + ((k == 1 || k == 2) ? fr : -fr), cy + (k >= 2 ? fr : -fr), fz);
    square.normals.emplace_back(0.0f, 0.0f, 1.0f);
  }
  square.indices = {0, 1, 2, 0, 2, 3};
  floor.upload(square);

  // A quad on the floor for its shadowed part, moved every frame (find_shadow_rect).
  SkinMesh rect = square;
  shadow_quad.upload(rect);
  glBindBuffer(GL_ARRAY_BUFFER, shadow_quad.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(4 * 6 * sizeof(float)), nullptr, GL_STREAM_DRAW);

  if (!make_backdrop(error)) return false;
  background.reset();  // only the backdrop uses it
  const float body_px = std::max(12.0f, settings.height / 40.0f);
  if (!imgui.init(body_px, error)) return false;
  // Every program is linked: Mesa's GLSL compiler keeps its library of built-in functions
  // (about 5 MB) until told it is not needed; a later compile builds it again.
  glReleaseShaderCompiler();
  return true;
}

// The camera's projection, with near and far planes around the organ (radius `radius`).
void Renderer::Impl::set_view_proj() {
  const double aspect = double(settings.width) / settings.height;
  const double dist = (camera.eye - camera.target).norm();
  near_plane = std::max(dist - 6 * radius, dist * 0.02);
  far_plane = dist + 8 * radius;
  if (endoscope) {
    // The tip may come within a few millimetres of the tissue; from inside the abdomen its
    // wall is at most a diameter away.
    near_plane = kEndoscopeNear;
    far_plane = 3 * abdomen.radius;
  }
  view = look_at(camera.eye, camera.target, camera.up);
  view_proj = perspective(camera.fov_deg, aspect, near_plane, far_plane) * view;
}

bool Renderer::Impl::make_backdrop(std::string& error) {
  glGenRenderbuffers(1, &backdrop_color);
  glBindRenderbuffer(GL_RENDERBUFFER, backdrop_color);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, fb->samples() > 1 ? fb->samples() : 0, GL_RGBA8, settings.width,
                                   settings.height);
  glGenFramebuffers(1, &backdrop_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, backdrop_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, backdrop_color);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    error = "OpenGL backdrop framebuffer incomplete";
    return false;
  }
  // Drawn in the frame's own target (with its depth: the floor hides the background) and
  // copied out.
  fb->bind_draw();
  glClearColor(0, 0, 0, 1);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  set_view_proj();
  if (settings.floor) draw_floor(floor, false);
  if (!endoscope) draw_background();  // the endoscope's picture is dark past its light's reach
  fb->blit_color_to(backdrop_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return true;
}

// The organ's positions into its buffer (llvmpipe maps its own storage: no staging copy; the
// last frame's drawing is done, so the map does not wait). Its normals and scalar follow in
// upload_normals(), after the shadow mask, which needs the positions only.
void Renderer::Impl::upload_positions(const vdm::NodeMat& x) {
  const size_t n = normals.size();
  float* const data = map_organ_buffer();
  if (!data) return;
  for (size_t i = 0; i < n; ++i) {
    float* d = data + i * 7;
    d[0] = float(x(Eigen::Index(i), 0));
    d[1] = float(x(Eigen::Index(i), 1));
    d[2] = float(x(Eigen::Index(i), 2));
  }
  glUnmapBuffer(GL_ARRAY_BUFFER);
}

// The organ's vertex buffer bound and mapped for writing, or null with the frame's error set.
float* Renderer::Impl::map_organ_buffer() {
  glBindBuffer(GL_ARRAY_BUFFER, organ_vbo);
  float* data = nullptr;
  if (fail_next_map) fail_next_map = false;
  else data = static_cast<float*>(glMapBufferRange(GL_ARRAY_BUFFER, 0, GLsizeiptr(normals.size() * 7 * sizeof(float)),
                                                   GL_MAP_WRITE_BIT));
  if (!data && frame_error.empty()) frame_error = "OpenGL could not map the organ's vertex buffer (out of memory?)";
  return data;
}

// Area-weighted vertex normals and the scalar into the organ's buffer. `mask_done` (or null):
// a fence after the shadow mask's pass, waited for once the normals are computed (the mask
// is rasterized meanwhile), before the main pass is binned. llvmpipe keeps a drawn scene's
// memory until it reuses the scene for a later one: a main pass begun while the mask was
// still being rasterized took another scene, and both scenes' memory stayed (8 MB at 40k
// nodes, measured); once the mask is done the main pass reuses its scene.
void Renderer::Impl::upload_normals(const vdm::NodeMat& x, const std::vector<float>* scalar, GLsync mask_done) {
  const size_t n = normals.size();
  for (auto& v : normals) v.setZero();
  const vdm::TriMat& tris = *triangles;
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const int a = tris(t, 0), b = tris(t, 1), c = tris(t, 2);
    const Eigen::Vector3d pa = x.row(a), pb = x.row(b), pc = x.row(c);
    const Eigen::Vector3f fn = (pb - pa).cross(pc - pa).cast<float>();  // area-weighted
    normals[size_t(a)] += fn;
    normals[size_t(b)] += fn;
    normals[size_t(c)] += fn;
  }
  if (mask_done) {
    glClientWaitSync(mask_done, GL_SYNC_FLUSH_COMMANDS_BIT, GL_TIMEOUT_IGNORED);
    glDeleteSync(mask_done);
  }
  if (scalar == &crease) find_creases(x);
  float* const data = map_organ_buffer();
  if (!data) return;
  for (size_t i = 0; i < n; ++i) {
    const float len = normals[i].norm();
    const Eigen::Vector3f nn = len > 0 ? Eigen::Vector3f(normals[i] / len) : Eigen::Vector3f::UnitZ();
    float* d = data + i * 7;
    d[3] = nn.x();
    d[4] = nn.y();
    d[5] = nn.z();
    d[6] = (scalar && scalar->size() == n) ? (*scalar)[i] : 0.0f;
  }
  glUnmapBuffer(GL_ARRAY_BUFFER);
}

// How deep each node lies in a crease, 0 (open or convex surface) to 0.5: the mean of its
// neighbours (over its triangles) lies outward of it along its normal by a fair part of its
// edges' mean length. Measured against the edges, not against the neighbours' mean offset
// (which is near zero on a regular patch, so that any slight kink would count as a crease).
// Shades the endoscope's tissue darker in folds, where its light reaches less. Needs
// upload_normals' accumulated normals.
void Renderer::Impl::find_creases(const vdm::NodeMat& x) {
  const size_t n = normals.size();
  neighbour_sum.assign(n, Eigen::Vector3f::Zero());
  neighbour_count.assign(n, 0.0f);
  edge_sum.assign(n, 0.0f);
  node_crease.resize(n);
  crease.resize(n);
  const vdm::TriMat& tris = *triangles;
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tris(t, k), b = tris(t, (k + 1) % 3), c = tris(t, (k + 2) % 3);
      neighbour_sum[size_t(a)] += (x.row(b) + x.row(c)).transpose().cast<float>();
      neighbour_count[size_t(a)] += 2.0f;
      edge_sum[size_t(a)] += float((x.row(b) - x.row(a)).norm() + (x.row(c) - x.row(a)).norm());
    }
  for (size_t i = 0; i < n; ++i) {
    const float len = normals[i].norm();
    node_crease[i] = 0;
    if (len <= 0 || neighbour_count[i] <= 0) continue;
    const Eigen::Vector3f p = x.row(Eigen::Index(i)).transpose().cast<float>();
    const Eigen::Vector3f off = neighbour_sum[i] / neighbour_count[i] - p;
    const float edge = edge_sum[i] / neighbour_count[i] + 1e-12f;
    const float depth = off.dot(normals[i] / len) / edge;  // > 0: the neighbours stand out of it
    node_crease[i] = std::clamp((depth - 0.1f) / 0.4f, 0.0f, 1.0f);
  }
  // Averaged over each node's triangles: a crease is a few edges wide; single nodes a little
  // inward of their neighbours (the mesh's own roughness) are not creases.
  std::fill(crease.begin(), crease.end(), 0.0f);
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const float mean =
        (node_crease[size_t(tris(t, 0))] + node_crease[size_t(tris(t, 1))] + node_crease[size_t(tris(t, 2))]) / 3.0f;
    for (int k = 0; k < 3; ++k) crease[size_t(tris(t, k))] += 2.0f * mean;
  }
  for (size_t i = 0; i < n; ++i) crease[i] = neighbour_count[i] > 0 ? 0.5f * crease[i] / neighbour_count[i] : 0.0f;
}

// This frame's camera: the endoscope's pose and light, or the framing camera as it is.
void Renderer::Impl::set_camera(const RenderScene& scene) {
  if (!endoscope) return;
  const double aspect = double(settings.width) / settings.height;
  camera = endoscope_camera(scene.camera_pose, tools::vertical_fov_deg(settings.endoscope.fov_deg, aspect));
  light_distance = std::max(exposure_distance(scene), 0.01);
}

// The scope's exposure, as its automatic exposure would set it for the organ in view: the
// median distance along the optical axis of the organ's nodes inside the field of view (not
// minding what hides them); the scene's light distance when none is.
double Renderer::Impl::exposure_distance(const RenderScene& scene) {
  if (!scene.positions) return scene.light_distance;
  const Eigen::Isometry3d from_world = scene.camera_pose.inverse();
  const double aspect = double(settings.width) / settings.height;
  const double tx = std::tan(settings.endoscope.fov_deg * 3.14159265358979323846 / 360.0), ty = tx / aspect;
  seen_depths.clear();
  const vdm::NodeMat& x = *scene.positions;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Eigen::Vector3d p = from_world * Eigen::Vector3d(x(i, 0), x(i, 1), x(i, 2));
    if (p.z() > kEndoscopeNear && std::abs(p.x()) < tx * p.z() && std::abs(p.y()) < ty * p.z()) seen_depths.push_back(p.z());
  }
  if (seen_depths.empty()) return scene.light_distance;
  auto mid = seen_depths.begin() + std::ptrdiff_t(seen_depths.size() / 2);
  std::nth_element(seen_depths.begin(), mid, seen_depths.end());
  return *mid;
}

// The endoscope's tissue material: its colours (sRGB), bumps, its texture's coarse period (m),
// and whether the texture is read at the world position (the wall) or the organ's rest
// position.
void Renderer::Impl::set_tissue(GlProgram& p, const Eigen::Vector3f& base, const Eigen::Vector3f& second, float bump,
                                double period, bool world) {
  glUniform3fv(p.uniform("u_base_srgb"), 1, base.data());
  glUniform3fv(p.uniform("u_second_srgb"), 1, second.data());
  glUniform1f(p.uniform("u_bump"), bump);
  glUniform1f(p.uniform("u_world_texture"), world ? 1.0f : 0.0f);
  glUniform1f(p.uniform("u_noise_scale"), float(1.0 / period));
  glUniform1i(p.uniform("u_noise"), 1);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_3D, noise_tex);
  glActiveTexture(GL_TEXTURE0);
}

InstrumentMeshes& Renderer::Impl::instrument_meshes(const InstrumentView& v) {
  const auto key = std::make_tuple(int(v.type), int(v.jaw_look), int(v.probe_look), v.radius, v.length, v.jaw_length, int(v.shape.kind), v.shape.size.x(),
                                   v.shape.size.y(), v.shape.size.z(), v.shape.rounding,
                                   static_cast<const void*>(v.shape.hull.get()));
  auto it = instruments.find(key);
  if (it != instruments.end()) return it->second;
  InstrumentMeshes m;
  if (v.type == tools::InstrumentDef::Type::probe && hook_look(v)) {
    const HookMeshes hook = probe_hook_meshes(v.radius, v.length);
    m.body.upload(hook.shaft);
    m.wire.upload(hook.hook);
  } else if (v.type == tools::InstrumentDef::Type::probe) {
    m.body.upload(probe_mesh(v.shape, v.radius, v.length));
  } else {
    m.body.upload(grasper_shaft_mesh(v.radius, v.length, v.jaw_length));
    m.jaws[0].upload(grasper_jaw_mesh(v.radius, v.jaw_length, +1, v.jaw_look));
    m.jaws[1].upload(grasper_jaw_mesh(v.radius, v.jaw_length, -1, v.jaw_look));
  }
  return instruments.emplace(key, m).first->second;
}

GpuMesh& Renderer::Impl::skin_mesh(const SkinMesh* s) {
  auto it = skins.find(s);
  if (it != skins.end()) return it->second;
  GpuMesh g;
  g.upload(*s);
  return skins.emplace(s, g).first->second;
}

GLuint Renderer::Impl::colormap_texture(ColorMapName name) {
  auto it = colormaps.find(name);
  if (it != colormaps.end()) return it->second;
  const auto& table = colormap_table(name);
  std::vector<std::uint8_t> rgb;
  for (const Rgb8& c : table) rgb.insert(rgb.end(), {c.r, c.g, c.b});
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, 256, 1, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  colormaps[name] = tex;
  return tex;
}

void Renderer::Impl::draw_instruments(const RenderScene& scene, GlProgram& prog, bool mask_only, int id_uniform,
                                      InstrumentParts parts) {
  const int u_model = prog.uniform("u_model");
  const int u_normal = mask_only ? -1 : prog.uniform("u_normal_matrix");
  auto draw_with = [&](const Eigen::Isometry3f& model, const GpuMesh& g) {
    glUniformMatrix4fv(u_model, 1, GL_FALSE, model.matrix().data());
    if (u_normal >= 0) {
      const Eigen::Matrix3f nm = model.linear();
      glUniformMatrix3fv(u_normal, 1, GL_FALSE, nm.data());
    }
    g.draw();
  };
  for (size_t k = 0; k < scene.instruments.size(); ++k) {
    const InstrumentView& v = scene.instruments[k];
    if (id_uniform >= 0)
      glUniform1ui(id_uniform, GLuint(instrument_id(int(k), std::max<int>(1, int(settings.organ_parts.size())))));
    const Eigen::Isometry3f frame = v.frame.cast<float>();
    InstrumentMeshes& param = instrument_meshes(v);
    // A plain probe is bare metal; a grasper's or a hook's shaft insulated.
    const bool insulated = v.type == tools::InstrumentDef::Type::grasper || (!v.skin && hook_look(v));
    const bool body = parts == InstrumentParts::all || (parts == InstrumentParts::shafts) == insulated;
    const bool metal = parts != InstrumentParts::shafts;
    if (body) draw_with(frame, v.skin ? skin_mesh(v.skin) : param.body);
    if (metal && !v.skin && hook_look(v)) draw_with(frame, param.wire);
    if (metal && v.type == tools::InstrumentDef::Type::grasper)
      for (int j = 0; j < 2; ++j) {
        const Eigen::Isometry3f model = frame * jaw_transform(v.jaw_length, v.jaw_opening, j == 0 ? +1 : -1);
        draw_with(model, v.jaw_skins[j] ? skin_mesh(v.jaw_skins[j]) : param.jaws[j]);
      }
  }
}

void Renderer::Impl::set_capsules(const RenderScene& scene) {
  capsule_a.clear();
  capsule_b.clear();
  box_centre.clear();
  box_half.clear();
  box_axes.clear();
  for (const InstrumentView& v : scene.instruments) {
    const bool boxy = v.type == tools::InstrumentDef::Type::probe &&
                      (v.shape.kind == tools::ProbeShape::Kind::box ||
                       (v.shape.kind == tools::ProbeShape::Kind::convex && v.shape.hull));
    if (boxy) {
      // A box probe casts its own shadow; a convex one that of its bounding box in the
      // hull's frame (rounded by the hull's rounding, if any).
      if (box_centre.size() == 4) continue;
      tools::InstrumentDef def;
      def.shape = v.shape;
      def.radius = v.radius;
      def.length = v.length;
      tools::InstrumentPose pose;
      pose.tip = v.frame.translation();
      pose.axis = v.frame.linear().col(2);
      vdm::ToolShape t = tools::probe_shape(def, pose, pose);
      t.pose = v.frame * (tools::instrument_frame(pose).inverse() * t.pose);  // the drawn frame exactly
      Eigen::Vector3d centre_local = Eigen::Vector3d::Zero(), half = t.half_size;
      if (t.kind == vdm::ToolShape::Kind::convex) {
        centre_local = 0.5 * (t.hull->lo + t.hull->hi);
        half = 0.5 * (t.hull->hi - t.hull->lo);
      }
      const Eigen::Vector3d c = t.pose * centre_local;
      box_centre.emplace_back(float(c.x()), float(c.y()), float(c.z()), float(t.rounding));
      box_half.emplace_back(float(half.x() - (t.kind == vdm::ToolShape::Kind::box ? t.rounding : 0.0)),
                            float(half.y() - (t.kind == vdm::ToolShape::Kind::box ? t.rounding : 0.0)),
                            float(half.z() - (t.kind == vdm::ToolShape::Kind::box ? t.rounding : 0.0)), 0.0f);
      box_axes.push_back(t.pose.linear().cast<float>());
      continue;
    }
    if (capsule_a.size() == 4) continue;
    const double r = v.radius, len = std::max(v.length, 2 * v.radius);
    const Eigen::Vector3d tip_centre = v.frame * Eigen::Vector3d(0, 0, -r);
    const Eigen::Vector3d handle = v.frame * Eigen::Vector3d(0, 0, -len);
    capsule_a.emplace_back(float(tip_centre.x()), float(tip_centre.y()), float(tip_centre.z()), float(r));
    capsule_b.emplace_back(float(handle.x()), float(handle.y()), float(handle.z()), 0.0f);
  }
}

void Renderer::Impl::shadow_mask_pass(const RenderScene& scene) {
  glBindFramebuffer(GL_FRAMEBUFFER, mask_fbo);
  glViewport(0, 0, kMaskSize, kMaskSize);
  glClearColor(1, 1, 1, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(mask_program.id());
  glUniformMatrix4fv(mask_program.uniform("u_floor_proj"), 1, GL_FALSE, floor_proj.data());
  const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
  glUniformMatrix4fv(mask_program.uniform("u_model"), 1, GL_FALSE, identity.data());
  // The organ is closed: the triangles facing away from the light alone cover its shadow
  // (half the triangles to set up and bin).
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glBindVertexArray(organ_vao);
  glDrawElements(GL_TRIANGLES, organ_count, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_CULL_FACE);
  draw_instruments(scene, mask_program, true);
  // Its mipmaps: the floor samples a coarser level, a cheap blur for a soft edge.
  glBindTexture(GL_TEXTURE_2D, mask_tex);
  glGenerateMipmap(GL_TEXTURE_2D);
}

void Renderer::Impl::find_shadow_rect(const RenderScene& scene) {
  // Where the casters (the organ's nodes, the instruments' bounding boxes) fall on the floor
  // along the key light, in the mask's square [-1, 1]^2.
  Eigen::AlignedBox2f cast;
  const Eigen::Matrix4f& P = floor_proj;
  auto add = [&](const Eigen::Vector3f& p) {
    cast.extend(Eigen::Vector2f(P(0, 0) * p.x() + P(0, 1) * p.y() + P(0, 2) * p.z() + P(0, 3),
                                P(1, 0) * p.x() + P(1, 1) * p.y() + P(1, 2) * p.z() + P(1, 3)));
  };
  const vdm::NodeMat& x = *scene.positions;
  for (Eigen::Index i = 0; i < x.rows(); ++i) add(Eigen::Vector3f(float(x(i, 0)), float(x(i, 1)), float(x(i, 2))));
  auto add_box = [&](const Eigen::Isometry3f& model, const Eigen::AlignedBox3f& box) {
    if (box.isEmpty()) return;
    for (int k = 0; k < 8; ++k) add(model * box.corner(Eigen::AlignedBox3f::CornerType(k)));
  };
  for (const InstrumentView& v : scene.instruments) {
    const Eigen::Isometry3f frame = v.frame.cast<float>();
    InstrumentMeshes& param = instrument_meshes(v);
    add_box(frame, v.skin ? skin_mesh(v.skin).box : param.body.box);
    if (v.type == tools::InstrumentDef::Type::grasper)
      for (int j = 0; j < 2; ++j)
        add_box(frame * jaw_transform(v.jaw_length, v.jaw_opening, j == 0 ? +1 : -1),
                v.jaw_skins[j] ? skin_mesh(v.jaw_skins[j]).box : param.jaws[j].box);
  }
  // The floor reads the mask at a coarser level (a blur a few texels wide): a margin of 16
  // texels. Past the mask's edge the floor reads its edge texels (clamped): a side reaching
  // the edge extends to the floor's end.
  const float margin = 16.0f * 2.0f / float(kMaskSize);
  const float floor_end = float(3 * radius / mask_half);
  Eigen::Vector4f r(-floor_end, -floor_end, floor_end, floor_end);
  if (!cast.isEmpty()) {
    const Eigen::Vector2f lo2 = cast.min().array() - margin, hi2 = cast.max().array() + margin;
    r = Eigen::Vector4f(lo2.x() <= -1 ? -floor_end : lo2.x(), lo2.y() <= -1 ? -floor_end : lo2.y(),
                        hi2.x() >= 1 ? floor_end : hi2.x(), hi2.y() >= 1 ? floor_end : hi2.y());
    r = r.cwiseMax(Eigen::Vector4f::Constant(-floor_end)).cwiseMin(Eigen::Vector4f::Constant(floor_end));
  }
  // Back to floor coordinates (metres).
  const float h = float(mask_half), cx = float(centre.x()), cy = float(centre.y());
  shadow_rect = Eigen::Vector4f(cx + h * r[0], cy + h * r[1], cx + h * r[2], cy + h * r[3]);
}

void Renderer::Impl::draw_floor(const GpuMesh& quad, bool shadowed) {
  const Eigen::Vector3f top(0.80f, 0.82f, 0.85f), bottom(0.47f, 0.49f, 0.53f);
  const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
  const Eigen::Matrix3f identity3 = Eigen::Matrix3f::Identity();
  glUseProgram(floor_program.id());
  glUniformMatrix4fv(floor_program.uniform("u_model"), 1, GL_FALSE, identity.data());
  glUniformMatrix3fv(floor_program.uniform("u_normal_matrix"), 1, GL_FALSE, identity3.data());
  glUniformMatrix4fv(floor_program.uniform("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(floor_program.uniform("u_top_srgb"), 1, top.data());
  glUniform3fv(floor_program.uniform("u_bottom_srgb"), 1, bottom.data());
  glUniform1f(floor_program.uniform("u_height"), float(settings.height));
  glUniform3fv(floor_program.uniform("u_floor_center"), 1, f3(centre).data());
  glUniform1f(floor_program.uniform("u_floor_radius"), float(3 * radius));
  glUniform1f(floor_program.uniform("u_mask_half"), float(mask_half));
  glUniform1i(floor_program.uniform("u_floor_shadow"), shadowed ? 1 : 0);
  glUniform1i(floor_program.uniform("u_mask"), 1);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, mask_tex);
  glActiveTexture(GL_TEXTURE0);
  quad.draw();
}

void Renderer::Impl::draw_background() {
  const Eigen::Vector3f top(0.80f, 0.82f, 0.85f), bottom(0.47f, 0.49f, 0.53f);
  glDepthFunc(GL_LEQUAL);
  glUseProgram(background.id());
  glUniform3fv(background.uniform("u_top_srgb"), 1, top.data());
  glUniform3fv(background.uniform("u_bottom_srgb"), 1, bottom.data());
  glUniform1f(background.uniform("u_height"), float(settings.height));
  glBindVertexArray(empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthFunc(GL_LESS);
  glBindVertexArray(0);
}

bool Renderer::Impl::build_material(Material m, std::string& error) {
  const char* defines[4] = {"MODE_TISSUE", "MODE_COLORMAP", "MODE_METAL", "MODE_WALL"};
  const std::string prefix = std::string("#define ") + defines[m] + "\n" + (endoscope ? "#define LIGHT_TIP\n" : "");
  const std::string fragment = "#version 450 core\n" + prefix + shaders::kMeshFragment;
  // The vertex shader with the same defines: after its first line (its #version).
  std::string vertex = shaders::kMeshVertex;
  vertex.insert(vertex.find('\n') + 1, prefix);
  return materials[m].build(vertex.c_str(), fragment.c_str(), error);
}

GlProgram& Renderer::Impl::use(Material m) {
  GlProgram& p = materials[m];
  if (!p.id()) {  // the colour-map material, dropped after init's check: built again from the same source
    std::string error;
    if (!build_material(m, error) && frame_error.empty())
      frame_error = "the colour-map shader could not be built again: " + error;
    glReleaseShaderCompiler();
  }
  glUseProgram(p.id());
  glUniformMatrix4fv(p.uniform("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(p.uniform("u_eye"), 1, f3(camera.eye).data());
  glUniform3fv(p.uniform("u_key_dir"), 1, f3(key_dir).data());
  glUniform3fv(p.uniform("u_fill_dir"), 1, f3(fill_dir).data());
  glUniform1i(p.uniform("u_colormap"), 0);
  glUniform1f(p.uniform("u_world_texture"), 0.0f);
  if (endoscope) {
    glUniform1i(p.uniform("u_noise"), 1);  // every material's vertex shader reads it
    glUniform1f(p.uniform("u_noise_scale"), float(1.0 / kTissueTexturePeriod));
    glUniform1f(p.uniform("u_light_distance"), float(light_distance));
    glUniform2f(p.uniform("u_viewport"), float(settings.width), float(settings.height));
  }
  glUniform1i(p.uniform("u_capsules"), settings.shadows ? int(capsule_a.size()) : 0);
  if (!capsule_a.empty()) {
    glUniform4fv(p.uniform("u_capsule_a"), GLsizei(capsule_a.size()), capsule_a[0].data());
    glUniform4fv(p.uniform("u_capsule_b"), GLsizei(capsule_b.size()), capsule_b[0].data());
  }
  glUniform1i(p.uniform("u_boxes"), settings.shadows ? int(box_centre.size()) : 0);
  if (!box_centre.empty()) {
    glUniform4fv(p.uniform("u_box_centre"), GLsizei(box_centre.size()), box_centre[0].data());
    glUniform4fv(p.uniform("u_box_half"), GLsizei(box_half.size()), box_half[0].data());
    glUniformMatrix3fv(p.uniform("u_box_axes"), GLsizei(box_axes.size()), GL_FALSE, box_axes[0].data());
  }
  return p;
}

bool Renderer::Impl::draw(const RenderScene& scene, const StressView* view, bool hud, Image& out) {
  return guarded([&] { draw_frame(scene, view, hud, out); });
}

bool Renderer::Impl::draw_ground_truth(const RenderScene& scene) {
  return guarded([&] { draw_ground_truth_pass(scene); });
}

// A frame's drawing (or reading), and whether it could be done: its own failures
// (frame_error) and any OpenGL error it raised. Errors left from before are cleared first (at
// most a few: each call returns one).
template <typename DrawFrame>
bool Renderer::Impl::guarded(const DrawFrame& draw_frame) {
  gl->make_current();
  frame_error.clear();
  for (int k = 0; k < 16; ++k)
    if (glGetError() == GL_NO_ERROR) break;
  draw_frame();
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR && frame_error.empty()) {
    char text[80];
    std::snprintf(text, sizeof text, "OpenGL error 0x%04x while drawing the frame%s", unsigned(e),
                  e == GL_OUT_OF_MEMORY ? " (out of memory)" : "");
    frame_error = text;
  }
  return frame_error.empty();
}

template <typename BeforePart>
void Renderer::Impl::draw_organ_parts(const BeforePart& before_part) {
  if (settings.organ_parts.empty()) {
    before_part(size_t(0), TissueLook::liver);
    glDrawElements(GL_TRIANGLES, organ_count, GL_UNSIGNED_INT, nullptr);
    return;
  }
  const long total = organ_count / 3;
  long first = 0;
  for (size_t i = 0; i < settings.organ_parts.size(); ++i) {
    const long count = std::min<long>(settings.organ_parts[i].triangles, total - first);
    before_part(i, settings.organ_parts[i].look);
    if (count > 0)
      glDrawElements(GL_TRIANGLES, GLsizei(3 * count), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(static_cast<uintptr_t>(3 * first) * sizeof(unsigned)));
    first += count;
  }
}

void Renderer::Impl::draw_frame(const RenderScene& scene, const StressView* view, bool hud, Image& out) {
  PassTimer timer;
  set_camera(scene);
  upload_positions(*scene.positions);
  set_capsules(scene);
  timer.mark("upload");
  GLsync mask_done = nullptr;
  if (settings.floor && settings.shadows) {
    shadow_mask_pass(scene);
    mask_done = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  }
  timer.mark("shadow mask");
  upload_normals(*scene.positions, view ? &scene.scalar : endoscope ? &crease : nullptr, mask_done);
  timer.mark("normals");

  fb->copy_color_from(backdrop_fbo);
  fb->bind_draw();
  glClearDepth(1.0);
  glClear(GL_DEPTH_BUFFER_BIT);
  timer.mark("backdrop");
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  set_view_proj();
  const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
  const Eigen::Matrix3f identity3 = Eigen::Matrix3f::Identity();

  // Organ (closed and oriented outward: back faces culled).
  GlProgram& organ = use(view ? kColormap : kTissue);
  glUniformMatrix4fv(organ.uniform("u_model"), 1, GL_FALSE, identity.data());
  glUniformMatrix3fv(organ.uniform("u_normal_matrix"), 1, GL_FALSE, identity3.data());
  if (view) {
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, colormap_texture(view->colormap));
    glUniform2f(organ.uniform("u_range"), float(view->lo), float(view->hi));
  }
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glBindVertexArray(organ_vao);
  // Organ by organ, each in its own tissue's colours (the stress view: all in one call).
  if (view) {
    glDrawElements(GL_TRIANGLES, organ_count, GL_UNSIGNED_INT, nullptr);
  } else {
    draw_organ_parts([&](size_t, TissueLook look) {
      const bool liver = look == TissueLook::liver;
      if (endoscope)  // the gallbladder: olive green, bluish where its wall is thin
        set_tissue(organ, liver ? Eigen::Vector3f(0.47f, 0.15f, 0.11f) : Eigen::Vector3f(0.36f, 0.42f, 0.22f),
                   liver ? Eigen::Vector3f(0.37f, 0.10f, 0.08f) : Eigen::Vector3f(0.26f, 0.34f, 0.30f), 0.12f,
                   kTissueTexturePeriod, false);
      else if (liver)
        glUniform3f(organ.uniform("u_base_srgb"), 0.55f, 0.20f, 0.16f);
      else
        glUniform3f(organ.uniform("u_base_srgb"), 0.38f, 0.46f, 0.24f);
    });
  }
  glDisable(GL_CULL_FACE);
  timer.mark("organ");
  // Instruments.
  GlProgram& metal = use(kMetal);
  if (endoscope) {  // black insulated shafts, bare steel jaws and wires
    glUniform3f(metal.uniform("u_base_srgb"), 0.05f, 0.05f, 0.055f);
    draw_instruments(scene, metal, false, -1, InstrumentParts::shafts);
    glUniform3f(metal.uniform("u_base_srgb"), 0.62f, 0.64f, 0.67f);
    draw_instruments(scene, metal, false, -1, InstrumentParts::metal);
  } else {
    glUniform3f(metal.uniform("u_base_srgb"), 0.62f, 0.64f, 0.67f);
    draw_instruments(scene, metal, false);
  }
  timer.mark("instruments");
  if (endoscope) {
    // The abdomen's wall, behind everything (drawn last: covered pixels cost little): pink
    // peritoneum with yellow fat, lit per vertex by the scope's light (no bumps).
    GlProgram& wall_program = use(kWall);
    glUniformMatrix4fv(wall_program.uniform("u_model"), 1, GL_FALSE, identity.data());
    glUniformMatrix3fv(wall_program.uniform("u_normal_matrix"), 1, GL_FALSE, identity3.data());
    set_tissue(wall_program, Eigen::Vector3f(0.78f, 0.50f, 0.47f), Eigen::Vector3f(0.80f, 0.62f, 0.46f), 0.0f,
               3 * kTissueTexturePeriod, true);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    wall.draw();
    glDisable(GL_CULL_FACE);
    timer.mark("wall");
  }

  // The floor where its shadow falls, behind what is drawn (the backdrop has the rest of
  // the floor and the background).
  if (settings.floor && settings.shadows) {
    find_shadow_rect(scene);
    const float z = float(floor_z), r[4] = {shadow_rect[0], shadow_rect[1], shadow_rect[2], shadow_rect[3]};
    const float quad[24] = {r[0], r[1], z, 0, 0, 1, r[2], r[1], z, 0, 0, 1, r[2], r[3], z, 0, 0, 1, r[0], r[3], z, 0, 0, 1};
    glBindBuffer(GL_ARRAY_BUFFER, shadow_quad.vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof quad, quad);
    draw_floor(shadow_quad, true);
  }
  glBindVertexArray(0);
  timer.mark("floor shadow");
  if (settings.antialias == Antialias::edge) {
    fb->resolve_and_read(out);
    timer.mark("read");
    smoother.apply(out);
    timer.mark("edge aa");
    if (hud || settings.gizmo) {
      draw_hud_layer(scene, view, hud, out);
      timer.mark("hud");
    }
    return;
  }
  if (hud || settings.gizmo) {
    glDisable(GL_DEPTH_TEST);
    draw_overlay(scene, view, hud);
    timer.mark("hud");
  }
  fb->resolve_and_read(out);
  timer.mark("resolve+read");
}

// The ground-truth targets of the scene's objects: the organ (closed, back faces culled, as in
// the pictures) and the instruments, each with its segmentation id; no floor, no background.
void Renderer::Impl::draw_ground_truth_pass(const RenderScene& scene) {
  if (!ground_truth) {
    auto pass = std::make_unique<GroundTruthPass>();
    std::string error;
    if (!pass->init(settings.width, settings.height, error)) {
      frame_error = error;
      return;
    }
    ground_truth = std::move(pass);
  }
  set_camera(scene);
  upload_positions(*scene.positions);
  upload_normals(*scene.positions, nullptr, nullptr);
  set_view_proj();
  GlProgram& program = ground_truth->begin(view_proj, view);
  const Eigen::Matrix4f identity = Eigen::Matrix4f::Identity();
  const Eigen::Matrix3f identity3 = Eigen::Matrix3f::Identity();
  glUniformMatrix4fv(program.uniform("u_model"), 1, GL_FALSE, identity.data());
  glUniformMatrix3fv(program.uniform("u_normal_matrix"), 1, GL_FALSE, identity3.data());
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glBindVertexArray(organ_vao);
  draw_organ_parts([&](size_t i, TissueLook) { ground_truth->set_id(unsigned(organ_id(int(i)))); });  // each organ its id
  glDisable(GL_CULL_FACE);
  draw_instruments(scene, program, false, program.uniform("u_id"));
  glBindVertexArray(0);
}

// The overlay (HUD, gizmo) on transparent black (ImGui blends colour by its alpha and alpha by ONE,
// ONE_MINUS_SRC_ALPHA: the layer is premultiplied), read back where it was drawn and
// composited over the smoothed frame: the same pixels as drawing it over the frame, to a
// level of rounding, with its text and panel edges left as ImGui anti-aliased them. Drawn in
// the frame's own (single-sample) target, whose picture has been read into `out` already and
// is not needed again (the next frame starts from the backdrop): no buffer of its own.
void Renderer::Impl::draw_hud_layer(const RenderScene& scene, const StressView* view, bool hud, Image& out) {
  fb->bind_draw();
  glClearColor(0, 0, 0, 0);
  glClear(GL_COLOR_BUFFER_BIT);
  glDisable(GL_DEPTH_TEST);
  draw_overlay(scene, view, hud);
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  if (imgui.drawn_bounds(x0, y0, x1, y1)) {
    if (hud_layer.width != x1 - x0 || hud_layer.height != y1 - y0) hud_layer = Image(x1 - x0, y1 - y0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(x0, settings.height - y1, x1 - x0, y1 - y0, GL_RGBA, GL_UNSIGNED_BYTE, hud_layer.rgba.data());
    flip_rows(hud_layer);
    composite_over(out, hud_layer, x0, y0);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// The HUD (when `hud`) and the orientation gizmo (when the settings ask for it), into the
// bound framebuffer.
void Renderer::Impl::draw_overlay(const RenderScene& scene, const StressView* view, bool hud) {
  ImDrawList* dl = imgui.begin(settings.width, settings.height);
  if (hud) draw_hud(dl, imgui, scene.hud, settings.width, settings.height, view);
  if (settings.gizmo) draw_gizmo(dl, imgui, camera, settings.width, settings.height);
  imgui.end();
}

std::unique_ptr<Renderer> Renderer::create(const RenderSettings& settings, const vdm::SurfaceMesh& rest, std::string& error) {
  std::unique_ptr<Renderer> r(new Renderer());
  r->impl_ = std::make_unique<Impl>();
  r->impl_->settings = settings;
  if (settings.camera_type == CameraType::endoscope) {
    r->impl_->endoscope = true;
    r->impl_->settings.floor = false;    // the abdomen's wall instead
    r->impl_->settings.shadows = false;  // the light is at the lens: shadows fall behind what casts them
  }
  if (settings.width < 16 || settings.height < 16 || settings.width > 8192 || settings.height > 8192) {
    error = "render size " + std::to_string(settings.width) + "x" + std::to_string(settings.height) +
            " out of range (16 to 8192)";
    return nullptr;
  }
  if (!r->impl_->init(rest, error)) return nullptr;
  return r;
}

Renderer::~Renderer() = default;

bool Renderer::draw_shaded(const RenderScene& scene, bool hud, Image& out) { return impl_->draw(scene, nullptr, hud, out); }

bool Renderer::draw_stress(const RenderScene& scene, const StressView& view, bool hud, Image& out) {
  return impl_->draw(scene, &view, hud, out);
}

bool Renderer::draw_views(const RenderScene& scene, const std::vector<View>& views, const ViewOptions& options,
                          const std::function<bool(View, ViewImage&)>& take) {
  bool ground_truth_drawn = false;
  ViewImage& image = impl_->view_image;
  for (View v : views) {
    const ViewRow& row = view_row(v);
    image.file = row.file;
    if (row.pass == ViewPass::picture) {
      if (!impl_->draw(scene, v == View::stress ? &options.stress : nullptr, options.hud, image.image)) return false;
    } else {
      if (!ground_truth_drawn && !impl_->draw_ground_truth(scene)) return false;
      ground_truth_drawn = true;
      if (!impl_->guarded([&] {
            switch (v) {
              case View::depth: impl_->ground_truth->read_camera_z(image.floats); break;
              case View::segmentation: impl_->ground_truth->read_ids(image.image); break;
              case View::normals: impl_->ground_truth->read_normals(image.image); break;
              case View::shaded:
              case View::stress: break;  // pictures, drawn above
            }
          }))
        return false;
    }
    if (!take(v, image)) return true;
  }
  return true;
}

CameraModel Renderer::camera_model() const {
  return render::camera_model(impl_->camera, impl_->settings.width, impl_->settings.height, impl_->near_plane,
                              impl_->far_plane);
}

const std::string& Renderer::error() const { return impl_->frame_error; }
void Renderer::fail_next_map_for_testing() { impl_->fail_next_map = true; }

const Camera& Renderer::camera() const { return impl_->camera; }
std::string Renderer::gl_renderer() const { return impl_->gl->renderer_name(); }

}  // namespace render
