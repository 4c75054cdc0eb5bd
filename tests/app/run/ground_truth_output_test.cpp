// The ground-truth views of a run, checked against the run's own exported mesh (--export-mesh)
// and its camera.json and poses.csv: each pixel's ray, from camera.json's intrinsics and the
// camera's pose in poses.csv, is cast at the frame's .vtu surface and at the probe's capsule
// (placed by its pose in poses.csv); the segmentation names what it meets first and the depth
// is where it meets the organ. A visible mesh node projected with the same numbers lands on
// the pixel whose depth puts it back in place. Two runs write the same bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "app/run/scene_run.hpp"
#include "render/npy_io.hpp"
#include "render/png_io.hpp"
#include "support/scratch_dir.hpp"
#include "support/ray_triangle.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kMiss = std::numeric_limits<double>::infinity();

std::string gto_read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The framing camera of the probe scene of the golden images.
const char* const kFramingCamera =
    "  camera: {eye: [0.2, -0.28, 0.22], target: [0.02, 0.0, 0.02], up: [0, 0, 1], fov_deg: 35}\n";
// A 30 degree endoscope looking down at the probe, moved by its script: aimed elsewhere, deeper
// and rolled at the last frame (t = 0.2 s).
const char* const kEndoscope =
    "  camera:\n    type: endoscope\n    port: [-0.04, -0.15, 0.13]\n    look_at: [0.05, 0.0, 0.06]\n"
    "    depth: 0.05\n    angle_deg: 30\n    roll_deg: 180\n    fov_deg: 75\n"
    "    script:\n      - {t: 0.1, look_at: [0.06, 0.01, 0.07]}\n      - {t: 0.2, depth: 0.06, roll_deg: 170}\n";

// The probe scene of the golden images at 320 x 240, with the ground-truth views, seen by
// `camera` (the render.camera lines).
fs::path gto_scene(const std::string& camera) {
  const fs::path p = vdmsim::test::scratch_dir("ground_truth_output") / "probe.yaml";
  std::ofstream(p) << "name: ground_truth\norgan:\n  mesh: "
                   << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "\n  material: {bulk_modulus: 20000, connectivity_modulus: 2000, density: 1060}\n"
                      "  fixed:\n    - {box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}\n"
                      "simulation:\n  frames: 3\n  dt: 0.1\n  effects: [contact]\n  solver: {method: direct}\n"
                      "instruments:\n  - type: probe\n    radius: 0.008\n    length: 0.25\n    script:\n"
                      "      - {t: 0.0, tip: [0.035, 0.0, 0.0603], axis: [0.2, 0, -1]}\n"
                      "      - {t: 0.2, tip: [0.035, 0.0, 0.0483]}\n"
                      "render:\n  width: 320\n  height: 240\n"
                   << camera << "  views: [shaded, depth, segmentation, normals]\n  hud: false\n";
  return p;
}

fs::path gto_run(const std::string& tag, const std::string& camera = kFramingCamera) {
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  EXPECT_TRUE(vdmsim::prepare_scene(gto_scene(camera).string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = (vdmsim::test::scratch_dir("ground_truth_output") / tag).string();
  opt.export_mesh = true;
  std::ostringstream out, err;
  EXPECT_EQ(vdmsim::run_scene(ps, opt, out, err, false), 0) << err.str();
  return opt.out_dir;
}

double gto_json_number(const std::string& js, const std::string& key) {
  const size_t at = js.find("\"" + key + "\": ");
  EXPECT_NE(at, std::string::npos) << key;
  return at == std::string::npos ? 0.0 : std::strtod(js.c_str() + at + key.size() + 4, nullptr);
}

// The pose of `object` at `frame` in poses.csv: world from object.
Eigen::Isometry3d gto_pose(const std::string& csv, int frame, const std::string& object, double* jaw_deg = nullptr) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "frame,object,px,py,pz,r00,r01,r02,r10,r11,r12,r20,r21,r22,jaw_deg");
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string f, name, cell;
    std::getline(row, f, ',');
    std::getline(row, name, ',');
    if (std::atoi(f.c_str()) != frame || name != object) continue;
    double v[13];
    for (double& x : v) {
      std::getline(row, cell, ',');
      x = std::strtod(cell.c_str(), nullptr);
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) pose.linear()(i, j) = v[3 + 3 * i + j];
    if (jaw_deg) *jaw_deg = v[12];
    return pose;
  }
  ADD_FAILURE() << "no row for " << object << " at frame " << frame;
  return Eigen::Isometry3d::Identity();
}

struct GtoMesh {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
};

// The .vtu's points and triangles (the writer's plain text).
GtoMesh gto_vtu(const std::string& vtu) {
  GtoMesh m;
  const size_t points = vtu.find('>', vtu.find("<DataArray", vtu.find("<Points>"))) + 1;
  std::istringstream p(vtu.substr(points, vtu.find("</DataArray>", points) - points));
  double x, y, z;
  while (p >> x >> y >> z) m.points.emplace_back(x, y, z);
  const size_t cells = vtu.find('>', vtu.find("Name=\"connectivity\"")) + 1;
  std::istringstream c(vtu.substr(cells, vtu.find("</DataArray>", cells) - cells));
  int a, b, d;
  while (c >> a >> b >> d) m.triangles.push_back({a, b, d});
  return m;
}

// A pinhole camera from camera.json and a pose from poses.csv, and ray casts through it.
struct GtoCamera {
  int w = 0, h = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Eigen::Isometry3d pose;
  Eigen::Vector3d ray(double u, double v) const {
    return (pose.linear() * Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1.0)).normalized();
  }
  Eigen::Vector3d project(const Eigen::Vector3d& p) const {  // (u, v, Z)
    const Eigen::Vector3d q = pose.inverse() * p;
    return {fx * q.x() / q.z() + cx, fy * q.y() / q.z() + cy, q.z()};
  }
};

// The mesh's triangles binned by the pixels their projection can cover (the box of their
// corners' projections, all in front of the camera), so that each pixel's ray is cast at a
// few triangles only; then the first hit of each pixel's ray.
std::vector<double> gto_cast_mesh(const GtoCamera& cam, const GtoMesh& m) {
  const int tile = 8, tw = (cam.w + tile - 1) / tile, th = (cam.h + tile - 1) / tile;
  std::vector<std::vector<int>> bins(size_t(tw * th));
  for (size_t k = 0; k < m.triangles.size(); ++k) {
    double u0 = 1e30, v0 = 1e30, u1 = -1e30, v1 = -1e30;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d q = cam.project(m.points[size_t(m.triangles[k][size_t(c)])]);
      EXPECT_GT(q.z(), 0.0);
      u0 = std::min(u0, q.x());
      u1 = std::max(u1, q.x());
      v0 = std::min(v0, q.y());
      v1 = std::max(v1, q.y());
    }
    const int a = std::max(0, int(std::floor(u0 - 1)) / tile), b = std::min(tw - 1, int(std::ceil(u1 + 1)) / tile);
    const int c = std::max(0, int(std::floor(v0 - 1)) / tile), d = std::min(th - 1, int(std::ceil(v1 + 1)) / tile);
    for (int ty = c; ty <= d; ++ty)
      for (int tx = a; tx <= b; ++tx) bins[size_t(ty * tw + tx)].push_back(int(k));
  }
  std::vector<double> t(size_t(cam.w * cam.h), kMiss);
  const Eigen::Vector3d o = cam.pose.translation();
  for (int v = 0; v < cam.h; ++v)
    for (int u = 0; u < cam.w; ++u) {
      const Eigen::Vector3d d = cam.ray(u, v);
      double best = kMiss;
      for (int k : bins[size_t((v / tile) * tw + u / tile)]) {
        const auto& tri = m.triangles[size_t(k)];
        best = std::min(best, test::ray_triangle(o, d, m.points[size_t(tri[0])], m.points[size_t(tri[1])],
                                               m.points[size_t(tri[2])]));
      }
      t[size_t(v * cam.w + u)] = best;
    }
  return t;
}

// Sphere tracing of a capsule (segment a-b, radius r).
double gto_ray_capsule(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double r) {
  const Eigen::Vector3d ab = b - a;
  double t = 0;
  for (int k = 0; k < 400 && t < 10; ++k) {
    const Eigen::Vector3d p = o + t * d;
    const double dist = (p - (a + std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) * ab)).norm() - r;
    if (dist < 1e-10) return t;
    t += dist;
  }
  return kMiss;
}


// The least of each kind of pixel a view must have for its check to mean something.
struct GtoCounts {
  int organ = 0, probe = 0, background = 0;
};

// Frame `frame` of the run in `dir` against the ray cast (the file's comment); the camera at
// `eye` in poses.csv.
void gto_check_frame(const fs::path& dir, int frame, const Eigen::Vector3d& eye, const GtoCounts& least) {
  const std::string camera_js = gto_read(dir / "camera.json"), poses = gto_read(dir / "poses.csv");
  GtoCamera cam;
  cam.w = int(gto_json_number(camera_js, "width"));
  cam.h = int(gto_json_number(camera_js, "height"));
  cam.fx = gto_json_number(camera_js, "fx");
  cam.fy = gto_json_number(camera_js, "fy");
  cam.cx = gto_json_number(camera_js, "cx");
  cam.cy = gto_json_number(camera_js, "cy");
  const double near = gto_json_number(camera_js, "near"), far = gto_json_number(camera_js, "far");
  ASSERT_EQ(cam.w, 320);
  ASSERT_EQ(cam.h, 240);
  EXPECT_GT(near, 0.0);
  EXPECT_GT(far, near);
  cam.pose = gto_pose(poses, frame, "camera");
  EXPECT_LT((cam.pose.translation() - eye).norm(), 1e-9);
  double jaw = -1;
  const Eigen::Isometry3d probe = gto_pose(poses, frame, "instruments[0]", &jaw);
  EXPECT_EQ(jaw, 0.0);
  EXPECT_LT((probe.translation() - Eigen::Vector3d(0.035, 0.0, 0.0483)).norm(), 1e-9);
  EXPECT_LT((probe.linear().col(2) - Eigen::Vector3d(0.2, 0, -1).normalized()).norm(), 1e-8);  // handle -> tip

  std::vector<float> depth;
  int dw = 0, dh = 0;
  std::string error;
  char name[64];
  std::snprintf(name, sizeof name, "depth/depth_%05d.npy", frame);
  ASSERT_TRUE(render::read_npy((dir / name).string(), depth, dw, dh, error)) << error;
  ASSERT_EQ(dw, cam.w);
  ASSERT_EQ(dh, cam.h);
  render::Image ids;
  std::snprintf(name, sizeof name, "segmentation/segmentation_%05d.png", frame);
  ASSERT_TRUE(render::read_png((dir / name).string(), ids, error)) << error;
  ASSERT_EQ(ids.width, cam.w);
  std::snprintf(name, sizeof name, "mesh/frame_%05d.vtu", frame);
  const GtoMesh mesh = gto_vtu(gto_read(dir / name));
  ASSERT_EQ(mesh.points.size(), 2562u);
  ASSERT_EQ(mesh.triangles.size(), 5120u);
  const std::string run_js = gto_read(dir / "run.json");
  EXPECT_NE(run_js.find("\"segmentation_ids\": {\"organ\": 1, \"instruments[0]\": 2}"), std::string::npos) << run_js;

  // The ray cast: the organ's surface, then the probe's capsule (radius 8 mm, length 25 cm: its
  // segment from z = -r to z = -(L - r) in its frame) wherever it is nearer.
  const std::vector<double> t_organ = gto_cast_mesh(cam, mesh);
  const Eigen::Vector3d seg_a = probe * Eigen::Vector3d(0, 0, -0.008), seg_b = probe * Eigen::Vector3d(0, 0, -0.242);
  std::vector<int> want(size_t(cam.w * cam.h), 0);
  std::vector<double> want_z(want.size(), 0.0);
  for (int v = 0; v < cam.h; ++v)
    for (int u = 0; u < cam.w; ++u) {
      const size_t i = size_t(v * cam.w + u);
      const Eigen::Vector3d d = cam.ray(u, v);
      const double t_probe = gto_ray_capsule(cam.pose.translation(), d, seg_a, seg_b, 0.008);
      if (t_organ[i] == kMiss && t_probe == kMiss) continue;
      want[i] = t_organ[i] < t_probe ? 1 : 2;
      if (want[i] == 1) want_z[i] = cam.project(cam.pose.translation() + t_organ[i] * d).z();
    }
  int organ = 0, probe_px = 0, background = 0, off_edge = 0, near_edge = 0;
  std::vector<double> errors;
  for (int v = 0; v < cam.h; ++v)
    for (int u = 0; u < cam.w; ++u) {
      const size_t i = size_t(v * cam.w + u);
      const int got = ids.rgba[i * 4];
      bool edge = false;  // the ray cast's id changes within the pixel's neighbours
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du)
          edge = edge || want[size_t(std::clamp(v + dv, 0, cam.h - 1) * cam.w + std::clamp(u + du, 0, cam.w - 1))] != want[i];
      if (got != want[i]) {
        ++(edge ? near_edge : off_edge);
        continue;
      }
      (got == 0 ? background : got == 1 ? organ : probe_px)++;
      if (got == 0) {
        EXPECT_EQ(depth[i], 0.0f) << "background pixel (" << u << ", " << v << ")";
      } else if (got == 1) {
        errors.push_back(std::abs(double(depth[i]) - want_z[i]));
      }
    }
  EXPECT_GT(organ, least.organ);
  EXPECT_GT(probe_px, least.probe);
  EXPECT_GE(background, least.background);
  EXPECT_EQ(off_edge, 0) << "pixels whose id differs from the ray cast's away from any silhouette";
  EXPECT_LT(near_edge, (organ + probe_px) / 100) << "silhouette pixels whose id differs from the ray cast's";
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors.back(), 1e-3) << "the worst organ pixel's depth error (m)";
  // The same triangles at the same pixel centres: float rounding only. Half a pixel of
  // difference in the convention (cx, cy) would give errors of a tenth of a millimetre.
  EXPECT_LT(errors[errors.size() / 2], 1e-6) << "the median organ pixel's depth error (m)";

  // Nodes of the mesh in view and facing the camera: projected with camera.json and the pose,
  // each lands on an organ pixel whose depth, back through the same numbers, puts it within a
  // pixel's footprint of where it is.
  std::vector<Eigen::Vector3d> normals(mesh.points.size(), Eigen::Vector3d::Zero());
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.points[size_t(tri[0])];
    const Eigen::Vector3d n = (mesh.points[size_t(tri[1])] - a).cross(mesh.points[size_t(tri[2])] - a);
    for (int c : tri) normals[size_t(c)] += n;
  }
  int checked = 0;
  for (size_t k = 0; k < mesh.points.size(); ++k) {
    const Eigen::Vector3d& p = mesh.points[k];
    const Eigen::Vector3d to_camera = (cam.pose.translation() - p).normalized();
    if (normals[k].normalized().dot(to_camera) < 0.5) continue;
    const Eigen::Vector3d q = cam.project(p);
    const int u = int(std::lround(q.x())), v = int(std::lround(q.y()));
    if (u < 1 || v < 1 || u >= cam.w - 1 || v >= cam.h - 1) continue;
    const size_t i = size_t(v * cam.w + u);
    const double t_node = (p - cam.pose.translation()).norm();
    if (t_organ[i] == kMiss || want[i] != 1 || t_organ[i] < t_node - 2e-3) continue;  // hidden by a fold or the probe
    ++checked;
    EXPECT_EQ(int(ids.rgba[i * 4]), 1) << "node " << k << " at pixel (" << u << ", " << v << ")";
    const double z = depth[i];
    const Eigen::Vector3d back = cam.pose * Eigen::Vector3d(z * (u - cam.cx) / cam.fx, z * (v - cam.cy) / cam.fy, z);
    const double footprint = q.z() / cam.fx;  // one pixel's width at the node (m)
    EXPECT_LT((back - p).norm(), 1.5 * footprint) << "node " << k << " at pixel (" << u << ", " << v << ")";
    EXPECT_NEAR(z, q.z(), 1.5 * footprint) << "node " << k;
  }
  EXPECT_GT(checked, 300);
}

}  // namespace

TEST(GroundTruthOutput, DepthAndSegmentationAgreeWithARayCastOfTheExportedMesh) {
  const fs::path dir = gto_run("one");
  gto_check_frame(dir, 2, Eigen::Vector3d(0.2, -0.28, 0.22), {20000, 500, 20000});  // the last: the probe pressed in
}

// The endoscope: its pose in poses.csv is the scope's through its port, frame by frame, as its
// script moves it; its depth and segmentation agree with the ray cast from that pose (the
// abdomen's wall is not an object: background).
TEST(GroundTruthOutput, TheEndoscopesPoseFollowsItsPortAndScriptAndItsImagesAgreeWithARayCast) {
  const fs::path dir = gto_run("endoscope", kEndoscope);
  const std::string poses = gto_read(dir / "poses.csv");
  const Eigen::Vector3d port(-0.04, -0.15, 0.13);
  const double vertical_fov = 2 * std::atan(std::tan(75 * M_PI / 360) * 240.0 / 320.0);
  const std::string camera_js = gto_read(dir / "camera.json");
  EXPECT_NEAR(gto_json_number(camera_js, "fy"), 120.0 / std::tan(vertical_fov / 2), 1e-6);
  EXPECT_NEAR(gto_json_number(camera_js, "fx"), 160.0 / std::tan(75 * M_PI / 360), 1e-6);
  // Frame f at t = 0.1 f: look_at moves from the first to the second point over 0.1 s, then the
  // depth from 5 to 6 cm and the roll from 180 to 170 degrees.
  const Eigen::Vector3d look0(0.05, 0.0, 0.06), look1(0.06, 0.01, 0.07);
  const Eigen::Vector3d looks[3] = {look0, look1, look1};
  const double depths[3] = {0.05, 0.05, 0.06}, rolls[3] = {180, 180, 170};
  for (int f = 0; f < 3; ++f) {
    const Eigen::Isometry3d pose = gto_pose(poses, f, "camera");
    const Eigen::Vector3d shaft = (looks[f] - port).normalized();
    // The tip (the optical centre) is `depth` past the port on the line to look_at.
    EXPECT_LT((pose.translation() - (port + depths[f] * shaft)).norm(), 1e-9) << "frame " << f;
    // The optics look 30 degrees off the shaft; roll 180 looks below it; the picture is level.
    const Eigen::Vector3d axis = pose.linear().col(2);
    EXPECT_NEAR(std::acos(std::clamp(axis.dot(shaft), -1.0, 1.0)) * 180 / M_PI, 30, 1e-6) << "frame " << f;
    EXPECT_LT(axis.z(), shaft.z()) << "frame " << f;
    EXPECT_NEAR(pose.linear().col(0).z(), 0, 1e-9) << "frame " << f;
    // The roll: the axis's turn about the shaft from straight below it (roll 180).
    const Eigen::Vector3d level_x = shaft.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d level_y = shaft.cross(level_x);  // toward the world's down
    const double turn = std::atan2(-axis.dot(level_x), axis.dot(level_y)) * 180 / M_PI;  // 0 at roll 180
    EXPECT_NEAR(turn, rolls[f] - 180, 1e-6) << "frame " << f;
  }
  gto_check_frame(dir, 2, port + 0.06 * (look1 - port).normalized(), {10000, 200, 0});
}

// Two runs of the same scene write the same bytes: every depth, segmentation and normals file,
// camera.json and poses.csv.
TEST(GroundTruthOutput, TwoRunsWriteTheSameBytes) {
  const fs::path a = gto_run("first"), b = gto_run("second");
  int files = 0;
  for (const char* folder : {"depth", "segmentation", "normals"})
    for (const auto& e : fs::directory_iterator(a / folder)) {
      const fs::path other = b / folder / e.path().filename();
      ASSERT_TRUE(fs::exists(other)) << other;
      EXPECT_EQ(gto_read(e.path()), gto_read(other)) << e.path().filename();
      ++files;
    }
  EXPECT_EQ(files, 9);
  EXPECT_EQ(gto_read(a / "camera.json"), gto_read(b / "camera.json"));
  const std::string poses = gto_read(a / "poses.csv");
  EXPECT_EQ(poses, gto_read(b / "poses.csv"));
  EXPECT_EQ(std::count(poses.begin(), poses.end(), '\n'), 1 + 3 * 2);  // the header, the camera and the probe per frame
}

// An instrument through a port: in every frame of poses.csv its shaft (the line through its tip
// along its z axis) passes through the port, behind the tip; the scene's keyframes give its tip
// by position and in port coordinates.
TEST(GroundTruthOutput, APortedInstrumentsShaftPassesItsPortInEveryFrame) {
  const fs::path p = vdmsim::test::scratch_dir("ground_truth_output") / "ported.yaml";
  const Eigen::Vector3d port(0.12, -0.1, 0.12);
  std::ofstream(p) << "name: ported\norgan:\n  mesh: "
                   << (fs::path(VDMSIM_SOURCE_DIR) / "assets/meshes/liver_L4.obj").string()
                   << "\n  fixed:\n    - {box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}\n"
                      "simulation:\n  frames: 4\n  dt: 0.1\n  effects: [contact]\n"
                      "instruments:\n  - type: grasper\n    port: [0.12, -0.1, 0.12]\n    script:\n"
                      "      - {t: 0.0, tip: [0.06, -0.03, 0.09]}\n"
                      "      - {t: 0.3, pan_deg: 150, tilt_deg: 35, depth: 0.11, roll_deg: 60}\n"
                      "      - {t: 0.5, depth: 0.09, jaw: closed}\n"
                      "render:\n  width: 64\n  height: 48\n"
                   << kEndoscope << "  views: [depth]\n";
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  vdmsim::RunOptions opt;
  opt.out_dir = (vdmsim::test::scratch_dir("ground_truth_output") / "ported").string();
  std::ostringstream out, err;
  ASSERT_EQ(vdmsim::run_scene(ps, opt, out, err, false), 0) << err.str();
  const std::string poses = gto_read(fs::path(opt.out_dir) / "poses.csv");
  for (int f = 0; f < 4; ++f) {
    const Eigen::Isometry3d pose = gto_pose(poses, f, "instruments[0]");
    const Eigen::Vector3d tip = pose.translation(), axis = pose.linear().col(2), to_port = port - tip;
    EXPECT_LT((to_port - to_port.dot(axis) * axis).norm(), 1e-6) << "frame " << f;  // poses.csv's digits
    EXPECT_LT(to_port.dot(axis), 0) << "frame " << f;
  }
  // Frame 3 (t = 0.3) is the port-coordinate keyframe: 11 cm in, 150 degrees from +x, 35 below.
  const Eigen::Vector3d at3 = gto_pose(poses, 3, "instruments[0]").translation();
  const double k = M_PI / 180;
  const Eigen::Vector3d want = port + 0.11 * Eigen::Vector3d(std::cos(35 * k) * std::cos(150 * k),
                                                            std::cos(35 * k) * std::sin(150 * k), -std::sin(35 * k));
  EXPECT_LT((at3 - want).norm(), 1e-6);
}

// Through the endoscope too (its light, texture, wall and exposure), two runs draw the same
// bytes: every shaded frame and ground-truth file, and poses.csv.
TEST(GroundTruthOutput, TheEndoscopesImagesAreTheSameRunAfterRun) {
  const fs::path a = gto_run("endoscope_first", kEndoscope), b = gto_run("endoscope_second", kEndoscope);
  int files = 0;
  for (const char* folder : {"frames", "depth", "segmentation", "normals"})
    for (const auto& e : fs::directory_iterator(a / folder)) {
      const fs::path other = b / folder / e.path().filename();
      ASSERT_TRUE(fs::exists(other)) << other;
      EXPECT_EQ(gto_read(e.path()), gto_read(other)) << folder << "/" << e.path().filename().string();
      ++files;
    }
  EXPECT_EQ(files, 12);
  EXPECT_EQ(gto_read(a / "poses.csv"), gto_read(b / "poses.csv"));
}
