#include "render/instrument_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace render {
namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxJawAngle = 30.0 * kPi / 180.0;

unsigned add_vertex(SkinMesh& m, const Eigen::Vector3f& p, const Eigen::Vector3f& n) {
  m.positions.push_back(p);
  m.normals.push_back(n.normalized());
  return static_cast<unsigned>(m.positions.size() - 1);
}
void add_triangle(SkinMesh& m, unsigned a, unsigned b, unsigned c) {
  m.indices.insert(m.indices.end(), {a, b, c});
}
}  // namespace

void append_cylinder(SkinMesh& m, double radius, double z0, double z1, int segments) {
  const unsigned base = static_cast<unsigned>(m.positions.size());
  for (int i = 0; i <= segments; ++i) {
    const double a = 2 * kPi * i / segments;
    const Eigen::Vector3f n(float(std::cos(a)), float(std::sin(a)), 0.0f);
    add_vertex(m, Eigen::Vector3f(float(radius * n.x()), float(radius * n.y()), float(z0)), n);
    add_vertex(m, Eigen::Vector3f(float(radius * n.x()), float(radius * n.y()), float(z1)), n);
  }
  const bool up = z1 > z0;
  for (int i = 0; i < segments; ++i) {
    const unsigned a = base + 2 * i, b = a + 1, c = a + 2, d = a + 3;
    if (up) {
      add_triangle(m, a, c, b);
      add_triangle(m, b, c, d);
    } else {
      add_triangle(m, a, b, c);
      add_triangle(m, b, d, c);
    }
  }
}

void append_hemisphere(SkinMesh& m, double radius, double zc, int sign, int segments) {
  const int rings = segments / 4;
  const unsigned base = static_cast<unsigned>(m.positions.size());
  for (int r = 0; r <= rings; ++r) {
    const double phi = 0.5 * kPi * r / rings;  // 0 at the equator, pi/2 at the pole
    for (int i = 0; i <= segments; ++i) {
      const double a = 2 * kPi * i / segments;
      const Eigen::Vector3f n(float(std::cos(phi) * std::cos(a)), float(std::cos(phi) * std::sin(a)),
                              float(sign * std::sin(phi)));
      add_vertex(m, Eigen::Vector3f(float(radius * n.x()), float(radius * n.y()), float(zc + radius * n.z())), n);
    }
  }
  const int row = segments + 1;
  for (int r = 0; r < rings; ++r)
    for (int i = 0; i < segments; ++i) {
      const unsigned a = base + r * row + i, b = a + 1, c = a + row, d = c + 1;
      if (sign > 0) {
        add_triangle(m, a, b, c);
        add_triangle(m, b, d, c);
      } else {
        add_triangle(m, a, c, b);
        add_triangle(m, b, c, d);
      }
    }
}

void append_disc(SkinMesh& m, double radius, double z, int sign, int segments) {
  const Eigen::Vector3f n(0, 0, float(sign));
  const unsigned centre = add_vertex(m, Eigen::Vector3f(0, 0, float(z)), n);
  for (int i = 0; i <= segments; ++i) {
    const double a = 2 * kPi * i / segments;
    add_vertex(m, Eigen::Vector3f(float(radius * std::cos(a)), float(radius * std::sin(a)), float(z)), n);
  }
  for (int i = 0; i < segments; ++i) {
    if (sign > 0)
      add_triangle(m, centre, centre + 1 + i, centre + 2 + i);
    else
      add_triangle(m, centre, centre + 2 + i, centre + 1 + i);
  }
}

void append_box(SkinMesh& m, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      n[axis] = side ? 1.0f : -1.0f;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      unsigned idx[4];
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector3f p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        p[v] = (k >= 2) ? hi[v] : lo[v];
        idx[k] = add_vertex(m, p, n);
      }
      if (side) {
        add_triangle(m, idx[0], idx[1], idx[2]);
        add_triangle(m, idx[0], idx[2], idx[3]);
      } else {
        add_triangle(m, idx[0], idx[2], idx[1]);
        add_triangle(m, idx[0], idx[3], idx[2]);
      }
    }
}

SkinMesh probe_mesh(double radius, double length) {
  SkinMesh m;
  const int seg = 32;
  append_hemisphere(m, radius, -radius, +1, seg);
  append_cylinder(m, radius, -radius, -std::max(length, 2 * radius), seg);
  append_disc(m, radius, -std::max(length, 2 * radius), -1, seg);
  return m;
}

SkinMesh grasper_shaft_mesh(double radius, double length, double jaw_length) {
  SkinMesh m;
  const int seg = 32;
  const double pivot = -jaw_length;
  // Shaft from a little behind the pivot to the handle end, a rounded clevis at the pivot.
  append_cylinder(m, radius, pivot - 0.6 * radius, -std::max(length, jaw_length + 2 * radius), seg);
  append_disc(m, radius, -std::max(length, jaw_length + 2 * radius), -1, seg);
  append_hemisphere(m, radius, pivot - 0.6 * radius, +1, seg);
  return m;
}

SkinMesh grasper_jaw_mesh(double radius, double jaw_length, int side) {
  SkinMesh m;
  const float w = float(0.8 * radius), t = float(0.45 * radius), L = float(jaw_length);
  // Closed, the jaws meet at y = 0: the upper jaw spans y in [0, t], the lower [-t, 0].
  const float y0 = side > 0 ? 0.0f : -t, y1 = side > 0 ? t : 0.0f;
  append_box(m, Eigen::Vector3f(-w, y0, -L), Eigen::Vector3f(w, y1, 0.0f));
  return m;
}

Eigen::Isometry3f jaw_transform(double jaw_length, double opening, int side) {
  const double angle = side * kMaxJawAngle * std::clamp(opening, 0.0, 1.0);
  const Eigen::Vector3f pivot(0, 0, float(-jaw_length));
  Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
  t.translate(pivot);
  t.rotate(Eigen::AngleAxisf(float(-angle), Eigen::Vector3f::UnitX()));
  t.translate(-pivot);
  return t;
}

}  // namespace render
