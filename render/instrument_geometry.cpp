#include "render/instrument_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace render {
namespace {
constexpr double kPi = 3.14159265358979323846;

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
  // The jaws' collision boxes (tools::jaw_shape), drawn as they are.
  tools::InstrumentDef def;
  def.radius = radius;
  def.jaw_length = jaw_length;
  const vdm::Vec3 h = tools::jaw_half_size(def);
  const float w = float(h.x()), t = float(2 * h.y()), L = float(2 * h.z());
  // Closed, the jaws meet at y = 0: the upper jaw spans y in [0, t], the lower [-t, 0].
  const float y0 = side > 0 ? 0.0f : -t, y1 = side > 0 ? t : 0.0f;
  append_box(m, Eigen::Vector3f(-w, y0, -L), Eigen::Vector3f(w, y1, 0.0f));
  return m;
}

void append_sweep(SkinMesh& m, const std::vector<Eigen::Vector2f>& path, const std::vector<float>& half_width, float y0,
                  float y1, bool closed) {
  const size_t n = path.size();
  if (n < 2) return;
  // Each point's across direction (in the x-z plane, perpendicular to the path there).
  std::vector<Eigen::Vector2f> across(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2f prev = closed ? path[(i + n - 1) % n] : path[i > 0 ? i - 1 : 0];
    const Eigen::Vector2f next = closed ? path[(i + 1) % n] : path[i + 1 < n ? i + 1 : n - 1];
    const Eigen::Vector2f t = (next - prev).normalized();
    across[i] = Eigen::Vector2f(t.y(), -t.x());
  }
  auto at = [&](size_t i, float side, float y) {
    const Eigen::Vector2f p = path[i] + side * half_width[i] * across[i];
    return Eigen::Vector3f(p.x(), y, p.y());
  };
  auto quad = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& d,
                  const Eigen::Vector3f& outward) {
    Eigen::Vector3f normal = (b - a).cross(d - a);
    if (normal.norm() < 1e-12f) normal = (c - b).cross(a - b);
    const bool flip = normal.dot(outward) < 0;
    normal = outward.normalized();
    const unsigned i0 = add_vertex(m, a, normal), i1 = add_vertex(m, b, normal), i2 = add_vertex(m, c, normal),
                   i3 = add_vertex(m, d, normal);
    if (flip) {
      add_triangle(m, i0, i3, i2);
      add_triangle(m, i0, i2, i1);
    } else {
      add_triangle(m, i0, i1, i2);
      add_triangle(m, i0, i2, i3);
    }
  };
  const size_t segments = closed ? n : n - 1;
  for (size_t k = 0; k < segments; ++k) {
    const size_t i = k, j = (k + 1) % n;
    const Eigen::Vector2f mid = 0.5f * (across[i] + across[j]);
    const Eigen::Vector3f out(mid.x(), 0.0f, mid.y());
    quad(at(i, 1, y1), at(j, 1, y1), at(j, -1, y1), at(i, -1, y1), Eigen::Vector3f::UnitY());   // top
    quad(at(i, 1, y0), at(i, -1, y0), at(j, -1, y0), at(j, 1, y0), -Eigen::Vector3f::UnitY());  // bottom
    quad(at(i, 1, y0), at(j, 1, y0), at(j, 1, y1), at(i, 1, y1), out);                          // one side
    quad(at(i, -1, y0), at(i, -1, y1), at(j, -1, y1), at(j, -1, y0), -out);                     // the other
  }
  if (closed) return;
  for (size_t e : {size_t(0), n - 1}) {  // the ends' caps, facing along the path
    const Eigen::Vector2f t = (e == 0 ? path[0] - path[1] : path[n - 1] - path[n - 2]).normalized();
    quad(at(e, 1, y0), at(e, -1, y0), at(e, -1, y1), at(e, 1, y1), Eigen::Vector3f(t.x(), 0.0f, t.y()));
  }
}

namespace {

// Scales a jaw's mesh along z onto [-L, 0], the collision box's length: a swept end's corners
// turn with the path and can reach a little past it.
void fit_length(SkinMesh& m, float L) {
  float lo = 0, hi = -L;
  for (const Eigen::Vector3f& p : m.positions) lo = std::min(lo, p.z()), hi = std::max(hi, p.z());
  const float scale = L / (hi - lo);
  for (Eigen::Vector3f& p : m.positions) p.z() = -L + (p.z() - lo) * scale;
}

}  // namespace

SkinMesh grasper_jaw_mesh(double radius, double jaw_length, int side, tools::InstrumentDef::JawLook look) {
  using Look = tools::InstrumentDef::JawLook;
  if (look == Look::box) return grasper_jaw_mesh(radius, jaw_length, side);
  tools::InstrumentDef def;
  def.radius = radius;
  def.jaw_length = jaw_length;
  const vdm::Vec3 h = tools::jaw_half_size(def);
  const float w = float(h.x()), t = float(2 * h.y()), L = float(2 * h.z());
  const float y0 = side > 0 ? 0.0f : -t, y1 = side > 0 ? t : 0.0f;
  SkinMesh m;
  const int samples = 24;
  if (look == Look::fenestrated) {
    // A rounded frame around a window over the front 80 % of the jaw, on a solid heel.
    const float heel = 0.25f * L, rail = 0.36f * w, mid = w - rail;  // the frame's bars and their centre line
    const float zb = -L + heel, zt = -(0.9f * mid + rail);            // the frame's ends: its front at the tip
    std::vector<Eigen::Vector2f> loop;
    for (int k = 0; k <= samples; ++k) {  // one side, back to front, round the tip, the other side
      const float a = 3.14159265f * float(k) / samples;
      loop.emplace_back(mid * std::cos(a), zt + (mid * 0.9f) * std::sin(a));
    }
    for (int k = 0; k <= samples; ++k) {
      const float a = 3.14159265f * (1.0f + float(k) / samples);
      loop.emplace_back(mid * std::cos(a), zb + (mid * 0.9f) * std::sin(a) * 0.4f);
    }
    append_sweep(m, loop, std::vector<float>(loop.size(), rail), y0, y1, true);
    append_box(m, Eigen::Vector3f(-w, y0, -L), Eigen::Vector3f(w, y1, zb - 0.2f * rail));
    fit_length(m, L);
    return m;
  }
  // Maryland: the centre line curves to +x toward the tip, the jaw tapering to a blunt point.
  std::vector<Eigen::Vector2f> line;
  std::vector<float> half;
  for (int k = 0; k <= samples; ++k) {
    const float s = float(k) / samples;
    line.emplace_back(0.55f * w * s * s, -L + s * L);
    half.push_back(w * (1.0f - 0.55f * s * s));
  }
  append_sweep(m, line, half, y0, y1, false);
  fit_length(m, L);
  return m;
}

void append_tube(SkinMesh& m, const std::vector<Eigen::Vector2f>& path, float tube_radius, int segments) {
  const size_t n = path.size();
  if (n < 2) return;
  const unsigned base = static_cast<unsigned>(m.positions.size());
  const int row = segments + 1;
  std::vector<Eigen::Vector3f> tangent(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2f t = (path[std::min(i + 1, n - 1)] - path[i > 0 ? i - 1 : 0]).normalized();
    tangent[i] = Eigen::Vector3f(t.x(), 0.0f, t.y());
    // The section's circle: its in-plane direction (across the path in x-z) and y.
    const Eigen::Vector3f across(t.y(), 0.0f, -t.x());
    for (int k = 0; k <= segments; ++k) {
      const float a = 2.0f * float(kPi) * float(k) / float(segments);
      const Eigen::Vector3f normal = std::cos(a) * across + std::sin(a) * Eigen::Vector3f::UnitY();
      add_vertex(m, Eigen::Vector3f(path[i].x(), 0.0f, path[i].y()) + tube_radius * normal, normal);
    }
  }
  for (size_t i = 0; i + 1 < n; ++i)
    for (int k = 0; k < segments; ++k) {
      const unsigned a = base + unsigned(i * row + k), b = a + 1, c = a + row, d = c + 1;
      // across x y = tangent: the ring turns counter-clockwise about the path, so (ring step)
      // x (path step) points outward.
      add_triangle(m, a, b, c);
      add_triangle(m, b, d, c);
    }
  for (size_t e : {size_t(0), n - 1}) {  // flat discs closing the ends
    const Eigen::Vector3f out = e == 0 ? Eigen::Vector3f(-tangent[0]) : tangent[n - 1];
    const unsigned centre = add_vertex(m, Eigen::Vector3f(path[e].x(), 0.0f, path[e].y()), out);
    const unsigned ring = static_cast<unsigned>(m.positions.size());
    for (int k = 0; k <= segments; ++k) add_vertex(m, m.positions[base + e * row + k], out);
    for (int k = 0; k < segments; ++k) {
      if (e == 0)
        add_triangle(m, centre, ring + k + 1, ring + k);
      else
        add_triangle(m, centre, ring + k, ring + k + 1);
    }
  }
}

HookMeshes probe_hook_meshes(double radius, double length) {
  const float r = float(radius), len = float(std::max(length, 2 * radius));
  HookMeshes h;
  // The insulation: the capsule's cylinder up to 2.2 r behind the tip, then a short taper
  // onto the wire's collar.
  const float taper0 = -2.2f * r, taper1 = -1.7f * r, collar = 0.3f * r;
  const Eigen::Vector2d slope = Eigen::Vector2d(taper1 - taper0, r - collar).normalized();  // (rho, z) outward
  std::vector<Eigen::Vector2d> p = {{0, -len}, {r, -len}, {r, -len}, {r, taper0}, {r, taper0}, {collar, taper1}, {collar, taper1}, {0, taper1}};
  std::vector<Eigen::Vector2d> n = {{0, -1}, {0, -1}, {1, 0}, {1, 0}, slope, slope, {0, 1}, {0, 1}};
  append_lathe(h.shaft, p, n, 32);
  // The wire: along the axis from inside the collar to a little behind the tip, over a
  // half turn to +x (its crown at the tip) and back toward the handle: a hook of 0.84 r across.
  // In units of r, then scaled about the capsule's tip centre (0, -r) if the tube would leave
  // the capsule (it does not with these sizes).
  const float wire = 0.13f, bend = 0.29f, crown = -0.5f;
  std::vector<Eigen::Vector2f> path;
  path.emplace_back(0.0f, -1.9f);
  const int arc = 16;
  for (int k = 0; k <= arc; ++k) {
    const float a = float(kPi) * float(k) / float(arc);
    path.emplace_back(bend - bend * std::cos(a), crown + bend * std::sin(a));
  }
  path.emplace_back(2 * bend, crown - 0.45f);
  // The farthest the tube reaches from the capsule's axis segment, in units of r.
  float farthest = 0;
  for (const Eigen::Vector2f& q : path) {
    const float along = std::min(q.y(), -1.0f);  // the axis segment's nearest point (z <= -r)
    farthest = std::max(farthest, Eigen::Vector2f(q.x(), q.y() - along).norm() + wire);
  }
  const float fit = farthest > 1.0f ? 1.0f / farthest : 1.0f;
  for (Eigen::Vector2f& q : path) q = r * Eigen::Vector2f(fit * q.x(), -1.0f + fit * (q.y() + 1.0f));
  append_tube(h.hook, path, r * wire * fit, 16);
  return h;
}

Eigen::Isometry3f jaw_transform(double jaw_length, double opening, int side) {
  return Eigen::Isometry3f(tools::jaw_transform(jaw_length, opening, side).matrix().cast<float>());
}

void append_lathe(SkinMesh& m, const std::vector<Eigen::Vector2d>& profile, const std::vector<Eigen::Vector2d>& normals,
                  int segments) {
  const unsigned base = static_cast<unsigned>(m.positions.size());
  const int row = segments + 1;
  for (size_t k = 0; k < profile.size(); ++k)
    for (int i = 0; i <= segments; ++i) {
      const double a = 2 * kPi * i / segments, c = std::cos(a), s = std::sin(a);
      add_vertex(m, Eigen::Vector3f(float(profile[k].x() * c), float(profile[k].x() * s), float(profile[k].y())),
                 Eigen::Vector3f(float(normals[k].x() * c), float(normals[k].x() * s), float(normals[k].y())));
    }
  for (size_t k = 0; k + 1 < profile.size(); ++k)
    for (int i = 0; i < segments; ++i) {
      const unsigned a = base + unsigned(k * row + i), b = a + 1, c = a + row, d = c + 1;
      // Outward when the profile runs from the handle (low z) toward the tip.
      add_triangle(m, a, b, c);
      add_triangle(m, b, d, c);
    }
}

namespace {

// A cylinder along z from z0 (handle) to z1 (tip) whose edges are rounded by e (both ends,
// as the collision shape).
SkinMesh rounded_cylinder_mesh(double r, double z0, double z1, double e, int seg) {
  std::vector<Eigen::Vector2d> p, n;
  const int arc = e > 0 ? 8 : 1;
  p.emplace_back(0, z0), n.emplace_back(0, -1);
  // Round the handle end's edge (from facing -z to facing out), then the tip's (out to +z).
  for (int k = 0; k <= arc; ++k) {
    const double a = -0.5 * 3.14159265358979323846 * (1.0 - double(k) / arc);
    p.emplace_back(r - e + e * std::cos(a), z0 + e + e * std::sin(a)), n.emplace_back(std::cos(a), std::sin(a));
  }
  for (int k = 0; k <= arc; ++k) {
    const double a = 0.5 * 3.14159265358979323846 * double(k) / arc;
    p.emplace_back(r - e + e * std::cos(a), z1 - e + e * std::sin(a)), n.emplace_back(std::cos(a), std::sin(a));
  }
  p.emplace_back(0, z1), n.emplace_back(0, 1);
  SkinMesh m;
  append_lathe(m, p, n, seg);
  return m;
}

// A box of half sizes h centred at c whose edges are rounded by e: a grid on the box's faces
// mapped onto the rounded surface (core point + e along the way out).
void append_rounded_box(SkinMesh& m, const vdm::Vec3& h, const vdm::Vec3& c, double e) {
  if (e <= 0) {
    append_box(m, (c - h).cast<float>(), (c + h).cast<float>());
    return;
  }
  const vdm::Vec3 core = (h.array() - e).max(0.0).matrix();
  // Grid coordinates along each axis: the flat part's ends plus arcs over the rounded bands.
  auto coords = [&](int axis) {
    std::vector<double> v;
    const int arc = 6;
    for (int k = arc; k >= 1; --k) v.push_back(-core[axis] - e * std::sin(0.5 * kPi * k / arc));
    v.push_back(-core[axis]);
    v.push_back(core[axis]);
    for (int k = 1; k <= arc; ++k) v.push_back(core[axis] + e * std::sin(0.5 * kPi * k / arc));
    return v;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      const std::vector<double> cu = coords(u), cw = coords(w);
      const unsigned base = static_cast<unsigned>(m.positions.size());
      for (double a : cu)
        for (double b : cw) {
          vdm::Vec3 q;
          q[axis] = side * h[axis];
          q[u] = a;
          q[w] = b;
          const vdm::Vec3 k = q.cwiseMax(-core).cwiseMin(core);
          const vdm::Vec3 n = (q - k).normalized();
          add_vertex(m, (c + k + e * n).cast<float>(), n.cast<float>());
        }
      const unsigned nw = unsigned(cw.size());
      for (unsigned i = 0; i + 1 < cu.size(); ++i)
        for (unsigned j = 0; j + 1 < nw; ++j) {
          const unsigned a = base + i * nw + j, b = a + 1, cc = a + nw, d = cc + 1;
          // (u, w, axis) is right-handed: counter-clockwise in (u, w) faces +axis.
          if (side > 0) {
            add_triangle(m, a, cc, d);
            add_triangle(m, a, d, b);
          } else {
            add_triangle(m, a, d, cc);
            add_triangle(m, a, b, d);
          }
        }
    }
}

}  // namespace

SkinMesh probe_mesh(const tools::ProbeShape& shape, double radius, double length) {
  const int seg = 32;
  const double len = std::max(length, 2 * radius);
  switch (shape.kind) {
    case tools::ProbeShape::Kind::capsule: return probe_mesh(radius, length);
    case tools::ProbeShape::Kind::cylinder: return rounded_cylinder_mesh(radius, -len, 0.0, shape.rounding, seg);
    case tools::ProbeShape::Kind::box: {
      SkinMesh m;
      append_rounded_box(m, 0.5 * shape.size, vdm::Vec3(0, 0, -0.5 * shape.size.z()), shape.rounding);
      return m;
    }
    case tools::ProbeShape::Kind::convex: {
      SkinMesh m;
      if (!shape.hull) return m;
      for (size_t k = 0; k < shape.hull->triangles.size(); ++k) {  // flat shaded: a normal per facet
        const Eigen::Vector3f n = shape.hull->normals[k].cast<float>();
        const unsigned a = add_vertex(m, shape.hull->vertices[shape.hull->triangles[k][0]].cast<float>(), n);
        const unsigned b = add_vertex(m, shape.hull->vertices[shape.hull->triangles[k][1]].cast<float>(), n);
        const unsigned c = add_vertex(m, shape.hull->vertices[shape.hull->triangles[k][2]].cast<float>(), n);
        add_triangle(m, a, b, c);
      }
      return m;
    }
  }
  return probe_mesh(radius, length);
}

}  // namespace render
