#include "app/scene/organ_generator.hpp"

#include <cmath>
#include <vector>

#include "engine/mesh_topology.hpp"
#include "engine/node_ordering.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

// Normalised ellipsoid distance: 1 on the ellipsoid's surface.
double ellipsoid(const vdm::Vec3& p, const vdm::Vec3& c, const vdm::Vec3& axes) {
  return ((p - c).array() / axes.array()).matrix().norm();
}

// Polynomial smooth minimum (blend width k).
double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

}  // namespace

double LiverShape::value(const vdm::Vec3& p) const {
  // Right lobe: large and thick; left lobe: flatter, reaching to -x; the dome is higher at
  // the back (+y) than at the front edge, as in a liver seen from the front.
  vdm::Vec3 q = p;
  q.z() -= 0.012 * (q.y() / 0.08);                  // tilt: front edge lower
  if (q.z() < 0.0) q.z() *= 1.6;                    // flatter underside (visceral surface)
  q.x() += 0.01 * std::tanh(q.y() / 0.05);          // a slight twist between front and back
  const double right = ellipsoid(q, vdm::Vec3(0.035, 0.0, 0.0), vdm::Vec3(0.10, 0.075, 0.06));
  const double left = ellipsoid(q, vdm::Vec3(-0.07, 0.012, 0.012), vdm::Vec3(0.085, 0.055, 0.03));
  const double blended = smooth_min(right, left, 0.35);
  // A shallow groove on the underside between the lobes.
  const double groove = 0.08 * std::exp(-std::pow((q.x() + 0.015) / 0.02, 2)) *
                        (q.z() < 0 ? std::min(1.0, -q.z() / 0.02) : 0.0);
  return blended + groove - 1.0;
}

namespace {

// The gradient of an implicit shape by central differences.
template <class Shape>
vdm::Vec3 central_gradient(const Shape& s, const vdm::Vec3& p) {
  const double h = 1e-6;
  vdm::Vec3 g;
  for (int d = 0; d < 3; ++d) {
    vdm::Vec3 a = p, b = p;
    a[d] += h;
    b[d] -= h;
    g[d] = (s.value(a) - s.value(b)) / (2 * h);
  }
  return g;
}

}  // namespace

vdm::Vec3 LiverShape::gradient(const vdm::Vec3& p) const { return central_gradient(*this, p); }

double GallbladderShape::value(const vdm::Vec3& p) const {
  // The fundus and body: an ellipsoid 6.8 cm long; the neck: a narrower one overlapping its
  // +x end, a little higher, blended in so that the body tapers into it.
  const double body = ellipsoid(p, vdm::Vec3(0.0, 0.0, 0.0), vdm::Vec3(0.034, 0.016, 0.015));
  const double neck = ellipsoid(p, vdm::Vec3(0.036, 0.0, 0.006), vdm::Vec3(0.02, 0.007, 0.007));
  return smooth_min(body, neck, 0.3) - 1.0;
}

vdm::Vec3 GallbladderShape::gradient(const vdm::Vec3& p) const { return central_gradient(*this, p); }

namespace {

// Newton steps along the gradient onto the zero level set.
template <class Shape>
vdm::Vec3 project(const Shape& s, vdm::Vec3 p) {
  for (int it = 0; it < 20; ++it) {
    const double f = s.value(p);
    const vdm::Vec3 g = s.gradient(p);
    const double g2 = g.squaredNorm();
    if (!(g2 > 0)) break;
    p -= f * g / g2;
    if (std::abs(f) < 1e-12) break;
  }
  return p;
}

// The surface point on the ray from the shape's centre along `dir` (first crossing).
template <class Shape>
vdm::Vec3 ray_hit(const Shape& s, const vdm::Vec3& dir) {
  const vdm::Vec3 c = s.center();
  double lo = 0.0, hi = 0.005;
  while (s.value(c + hi * dir) < 0.0) {
    lo = hi;
    hi += 0.005;
  }
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (s.value(c + mid * dir) < 0.0 ? lo : hi) = mid;
  }
  return c + 0.5 * (lo + hi) * dir;
}

// The shape meshed: the icosphere's nodes projected along its rays from the shape's centre,
// then relaxed along the surface.
// `stretch` scales the icosphere's directions before they are cast (empty: as they are).
template <class Shape>
vdm::SurfaceMesh mesh_shape(const Shape& shape, int level, int relax_iterations, const vdm::Vec3* stretch) {
  vdm::SurfaceMesh mesh = vdm::make_icosphere(1.0, level);
  const int n = mesh.node_count();
  for (int i = 0; i < n; ++i) {
    vdm::Vec3 dir = mesh.positions.row(i).transpose();
    if (stretch) dir = dir.cwiseProduct(*stretch).normalized();
    mesh.positions.row(i) = ray_hit(shape, dir).transpose();
  }
  // Tangential relaxation: move each node toward the average of its neighbours, remove the
  // normal part of the move, and project back onto the surface. Evens out the triangles that
  // the radial projection stretched over the elongated lobes.
  const auto edges = vdm::unique_edges(mesh.triangles);
  std::vector<vdm::Vec3> sum(n);
  std::vector<int> count(n);
  for (int it = 0; it < relax_iterations; ++it) {
    std::fill(sum.begin(), sum.end(), vdm::Vec3::Zero());
    std::fill(count.begin(), count.end(), 0);
    for (const auto& e : edges) {
      sum[e[0]] += mesh.positions.row(e[1]).transpose();
      sum[e[1]] += mesh.positions.row(e[0]).transpose();
      ++count[e[0]];
      ++count[e[1]];
    }
    vdm::NodeMat next = mesh.positions;
    for (int i = 0; i < n; ++i) {
      const vdm::Vec3 p = mesh.positions.row(i);
      const vdm::Vec3 normal = shape.gradient(p).normalized();
      vdm::Vec3 move = sum[i] / count[i] - p;
      move -= move.dot(normal) * normal;
      next.row(i) = project(shape, p + 0.5 * move).transpose();
    }
    mesh.positions = next;
  }
  // The icosphere numbers its nodes level by level (neighbours' indices about a quarter of N
  // apart): in locality order every pass of the engine over nodes, edges and triangles walks
  // memory nearly in order.
  vdm::renumber_for_locality(mesh);
  return mesh;
}

}  // namespace

vdm::SurfaceMesh make_liver_mesh(int level, int relax_iterations) {
  return mesh_shape(LiverShape(), level, relax_iterations, nullptr);
}

vdm::SurfaceMesh make_gallbladder_mesh(int level, int relax_iterations) {
  const GallbladderShape shape;
  const vdm::Vec3 stretch = shape.stretch();
  return mesh_shape(shape, level, relax_iterations, &stretch);
}

}  // namespace vdmsim
