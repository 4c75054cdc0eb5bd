// The pictures match what collides: every vertex of a drawn probe or jaw lies on the surface
// of its collision shape (tools::probe_shape, tools::jaw_shape, tools::shaft_shape).
#include <gtest/gtest.h>

#include "engine/convex_hull.hpp"
#include "engine/shapes.hpp"
#include "render/instrument_geometry.hpp"

namespace render {
namespace {

// Largest |signed distance| of the mesh's vertices (placed by `place`) from the shape's surface,
// over vertices with z above `z_min` in the instrument frame.
double off_surface(const SkinMesh& m, const vdm::ToolShape& t, const Eigen::Isometry3d& place, double z_min) {
  double worst = 0;
  for (const Eigen::Vector3f& v : m.positions) {
    if (v.z() < z_min) continue;
    vdm::Vec3 p, n;
    worst = std::max(worst, std::abs(vdm::tool_distance(t, place * v.cast<double>(), p, n)));
  }
  return worst;
}

TEST(InstrumentGeometry, DrawnProbesLieOnTheirCollisionShapes) {
  tools::InstrumentDef def;
  def.radius = 0.005;
  def.length = 0.2;
  tools::InstrumentPose pose;
  pose.tip = vdm::Vec3::Zero();
  pose.axis = vdm::Vec3::UnitZ();  // the instrument frame is the world
  auto hull = std::make_shared<vdm::ConvexHull>();
  std::vector<vdm::Vec3> pts;
  const vdm::SurfaceMesh ico = vdm::make_icosphere(0.01, 1);
  for (int i = 0; i < ico.node_count(); ++i) pts.push_back(ico.positions.row(i).transpose() - vdm::Vec3(0, 0, 0.01));
  std::string error;
  ASSERT_TRUE(vdm::convex_hull(pts, *hull, error)) << error;
  struct Case {
    tools::ProbeShape::Kind kind;
    double rounding;
  };
  for (const Case c : {Case{tools::ProbeShape::Kind::capsule, 0}, Case{tools::ProbeShape::Kind::cylinder, 0},
                       Case{tools::ProbeShape::Kind::cylinder, 0.002}, Case{tools::ProbeShape::Kind::box, 0},
                       Case{tools::ProbeShape::Kind::box, 0.001}, Case{tools::ProbeShape::Kind::convex, 0}}) {
    def.shape.kind = c.kind;
    def.shape.rounding = c.rounding;
    def.shape.size = vdm::Vec3(0.02, 0.008, 0.05);
    def.shape.hull = hull;
    const SkinMesh m = probe_mesh(def.shape, def.radius, def.length);
    ASSERT_FALSE(m.positions.empty());
    // The working half (the capsule's drawn handle end is flat).
    const double err = off_surface(m, tools::probe_shape(def, pose, pose), Eigen::Isometry3d::Identity(), -0.5 * def.length);
    EXPECT_LT(err, 1e-6) << "shape " << int(c.kind) << " rounding " << c.rounding;
  }
}

TEST(InstrumentGeometry, DrawnJawsLieOnTheirCollisionBoxes) {
  tools::InstrumentDef def;
  def.type = tools::InstrumentDef::Type::grasper;
  def.radius = 0.005;
  def.jaw_length = 0.015;
  tools::InstrumentPose pose;
  pose.tip = vdm::Vec3(0.01, 0.02, 0.03);
  pose.axis = vdm::Vec3(0.2, -0.3, -1).normalized();
  for (double opening : {0.0, 0.35, 1.0}) {
    pose.jaw_opening = opening;
    for (int side : {+1, -1}) {
      const SkinMesh m = grasper_jaw_mesh(def.radius, def.jaw_length, side);
      const Eigen::Isometry3d place =
          tools::instrument_frame(pose) * Eigen::Isometry3d(jaw_transform(def.jaw_length, opening, side).matrix().cast<double>());
      EXPECT_LT(off_surface(m, tools::jaw_shape(def, pose, pose, side), place, -1.0), 1e-6)
          << "opening " << opening << " side " << side;
    }
  }
}

TEST(InstrumentGeometry, DrawnGrasperShaftLiesOnItsCollisionCapsule) {
  tools::InstrumentDef def;
  def.type = tools::InstrumentDef::Type::grasper;
  def.radius = 0.005;
  def.length = 0.25;
  def.jaw_length = 0.015;
  tools::InstrumentPose pose;
  pose.tip = vdm::Vec3(0.01, 0.02, 0.03);
  pose.axis = vdm::Vec3(0.2, -0.3, -1).normalized();
  const SkinMesh m = grasper_shaft_mesh(def.radius, def.length, def.jaw_length);
  // The working half (the drawn handle end is flat, the capsule's rounded).
  EXPECT_LT(off_surface(m, tools::shaft_shape(def, pose, pose), tools::instrument_frame(pose), -0.5 * def.length), 1e-6);
}

}  // namespace

namespace {
// The enclosed volume of a closed mesh by the divergence theorem: positive when its triangles
// wind outward.
double enclosed_volume(const SkinMesh& m) {
  double v = 0;
  for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
    const Eigen::Vector3d a = m.positions[m.indices[k]].cast<double>(), b = m.positions[m.indices[k + 1]].cast<double>(),
                          c = m.positions[m.indices[k + 2]].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}
}  // namespace

TEST(InstrumentGeometry, AHookLiesWithinItsCapsuleAndTurnsOverAtTheTip) {
  tools::InstrumentDef def;
  def.radius = 0.004;
  def.length = 0.3;
  tools::InstrumentPose pose;
  pose.tip = vdm::Vec3::Zero();
  pose.axis = vdm::Vec3::UnitZ();
  const vdm::ToolShape capsule = tools::probe_shape(def, pose, pose);
  const HookMeshes h = probe_hook_meshes(def.radius, def.length);
  ASSERT_FALSE(h.shaft.indices.empty());
  ASSERT_FALSE(h.hook.indices.empty());
  const double r = def.radius;
  for (const SkinMesh* m : {&h.shaft, &h.hook}) {
    for (const Eigen::Vector3f& v : m->positions) {
      if (v.z() < -0.5 * def.length) continue;  // the drawn handle end is flat, the capsule's rounded
      vdm::Vec3 p, n;
      EXPECT_LE(vdm::tool_distance(capsule, v.cast<double>(), p, n), 1e-6) << "outside the capsule at " << v.transpose();
    }
    for (const Eigen::Vector3f& n : m->normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
  }
  // The insulation is the capsule's cylinder behind its taper.
  int on_cylinder = 0;
  for (const Eigen::Vector3f& v : h.shaft.positions) {
    if (v.z() < -0.5 * def.length || v.z() > -2.2 * r + 1e-6 || v.head<2>().norm() < 1e-9) continue;
    vdm::Vec3 p, n;
    EXPECT_NEAR(vdm::tool_distance(capsule, v.cast<double>(), p, n), 0.0, 1e-6);
    ++on_cylinder;
  }
  EXPECT_GT(on_cylinder, 0);
  // Both meshes are closed and wind outward: the wire's volume is about its section times its
  // length (1.4 r of stem + a half turn of 0.29 r + 0.45 r back, 0.13 r in radius; its
  // section a 16-gon, 2.6 % smaller than the circle).
  EXPECT_GT(enclosed_volume(h.shaft), 0.9 * 3.14159 * r * r * (def.length - 2.2 * r));
  const double wire_length = 1.4 * r + 3.14159 * 0.29 * r + 0.45 * r, section = 3.14159 * std::pow(0.13 * r, 2);
  EXPECT_NEAR(enclosed_volume(h.hook), section * wire_length, 0.04 * section * wire_length);
  // Its crown is at the tip; it comes back on the +x side only.
  float z_hi = -1, x_lo = 1, x_hi = -1;
  for (const Eigen::Vector3f& v : h.hook.positions) z_hi = std::max(z_hi, v.z()), x_lo = std::min(x_lo, v.x()), x_hi = std::max(x_hi, v.x());
  EXPECT_GT(z_hi, -0.1 * r);
  EXPECT_GT(x_hi, 0.6 * r);
  EXPECT_GT(x_lo, -0.2 * r);
}

}  // namespace render

// The jaws' looks are drawn within their collision boxes (what is seen touching is what
// touches), closed shut against each other; the fenestrated jaw has a window through it, the
// Maryland jaw curves to the side toward its tip.
TEST(InstrumentGeometry, JawLooksStayWithinTheirCollisionBoxes) {
  using Look = tools::InstrumentDef::JawLook;
  tools::InstrumentDef def;
  def.radius = 0.005;
  def.jaw_length = 0.02;
  const vdm::Vec3 h = tools::jaw_half_size(def);
  const float w = float(h.x()), t = float(2 * h.y()), L = float(2 * h.z()), eps = 1e-6f;
  for (Look look : {Look::fenestrated, Look::maryland})
    for (int side : {+1, -1}) {
      const render::SkinMesh m = render::grasper_jaw_mesh(def.radius, def.jaw_length, side, look);
      ASSERT_FALSE(m.indices.empty());
      float y_lo = 1, y_hi = -1;
      for (const Eigen::Vector3f& p : m.positions) {
        EXPECT_LE(std::abs(p.x()), w + eps);
        EXPECT_GE(p.z(), -L - eps);
        EXPECT_LE(p.z(), eps);
        y_lo = std::min(y_lo, p.y());
        y_hi = std::max(y_hi, p.y());
      }
      EXPECT_NEAR(y_lo, side > 0 ? 0.0f : -t, eps);  // the closed jaws meet at y = 0
      EXPECT_NEAR(y_hi, side > 0 ? t : 0.0f, eps);
      for (const Eigen::Vector3f& n : m.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-4f);
    }
  // Seen along y (the way the jaws close), the fenestrated jaw covers its rim but not its middle.
  auto covered = [](const render::SkinMesh& m, float x, float z) {
    for (size_t k = 0; k + 2 < m.indices.size(); k += 3) {
      const Eigen::Vector3f &a = m.positions[m.indices[k]], &b = m.positions[m.indices[k + 1]], &c = m.positions[m.indices[k + 2]];
      auto edge = [&](const Eigen::Vector3f& p, const Eigen::Vector3f& q) {
        return (q.x() - p.x()) * (z - p.z()) - (q.z() - p.z()) * (x - p.x());
      };
      const float e0 = edge(a, b), e1 = edge(b, c), e2 = edge(c, a);
      if ((e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0)) return true;
    }
    return false;
  };
  const render::SkinMesh fen = render::grasper_jaw_mesh(def.radius, def.jaw_length, +1, Look::fenestrated);
  EXPECT_FALSE(covered(fen, 0.0f, -0.5f * L)) << "the window";
  EXPECT_TRUE(covered(fen, 0.8f * w, -0.5f * L)) << "a rail";
  EXPECT_TRUE(covered(fen, 0.0f, -0.95f * L)) << "the heel";
  const render::SkinMesh box = render::grasper_jaw_mesh(def.radius, def.jaw_length, +1, Look::box);
  EXPECT_TRUE(covered(box, 0.1f * w, -0.47f * L));  // (off its faces' diagonals)
  // The Maryland jaw's tip lies to +x of its heel's centre.
  const render::SkinMesh md = render::grasper_jaw_mesh(def.radius, def.jaw_length, +1, Look::maryland);
  float tip_x = 0, tip_n = 0;
  for (const Eigen::Vector3f& p : md.positions)
    if (p.z() > -0.05f * L) tip_x += p.x(), tip_n += 1;
  ASSERT_GT(tip_n, 0);
  EXPECT_GT(tip_x / tip_n, 0.3f * w);
  EXPECT_FALSE(covered(md, -0.9f * w, -0.02f * L)) << "tapered and curved away at the tip";
}
