#include "engine/cotangent_laplacian.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace vdm {
namespace {

// An intrinsic triangulation as half-edges: half-edge 3 t + k of triangle t goes from
// `from[h]` to the origin of the next one in its triangle; `length[h]` is its edge's length
// (the same for both halves), `twin[h]` the other half.
struct HalfEdges {
  std::vector<int> from, twin;
  std::vector<double> length;
  static int next(int h) { return h - h % 3 + (h % 3 + 1) % 3; }
  static int prev(int h) { return h - h % 3 + (h % 3 + 2) % 3; }
};

HalfEdges build_half_edges(const NodeMat& x, const TriMat& tris) {
  HalfEdges he;
  const int count = 3 * int(tris.rows());
  he.from.resize(size_t(count));
  he.twin.assign(size_t(count), -1);
  he.length.resize(size_t(count));
  std::map<std::pair<int, int>, int> by_ends;
  for (int t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int h = 3 * t + k, a = tris(t, k), b = tris(t, (k + 1) % 3);
      he.from[size_t(h)] = a;
      he.length[size_t(h)] = (x.row(b) - x.row(a)).norm();
      by_ends[{a, b}] = h;
    }
  for (const auto& [ends, h] : by_ends) {
    const auto it = by_ends.find({ends.second, ends.first});
    if (it != by_ends.end()) he.twin[size_t(h)] = it->second;
  }
  return he;
}

// Twice the area of a triangle of side lengths a, b, c (Kahan's stable form of Heron's).
double double_area(double a, double b, double c) {
  if (a < b) std::swap(a, b);
  if (b < c) std::swap(b, c);
  if (a < b) std::swap(a, b);
  const double p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
  return 0.5 * std::sqrt(std::max(p, 0.0));
}

// cot of the angle opposite half-edge h in its triangle.
double cot_opposite(const HalfEdges& he, int h) {
  const double c = he.length[size_t(h)], a = he.length[size_t(HalfEdges::next(h))],
               b = he.length[size_t(HalfEdges::prev(h))];
  const double area2 = double_area(a, b, c);
  if (!(area2 > 0.0)) return 0.0;  // a degenerate corner carries no weight
  return (a * a + b * b - c * c) / (2.0 * area2);
}

// The angle at the origin of half-edge h, between h and the previous half-edge reversed.
double angle_at_origin(const HalfEdges& he, int h) {
  const double a = he.length[size_t(h)], b = he.length[size_t(HalfEdges::prev(h))],
               c = he.length[size_t(HalfEdges::next(h))];
  const double cosine = (a * a + b * b - c * c) / (2.0 * a * b);
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

// Flips the edge of half-edge h (and its twin) to join the two opposite corners.
void flip(HalfEdges& he, int h) {
  const int g = he.twin[size_t(h)];
  const int h1 = HalfEdges::next(h), h2 = HalfEdges::prev(h);  // j->k, k->i
  const int g1 = HalfEdges::next(g), g2 = HalfEdges::prev(g);  // i->l, l->j
  const int k = he.from[size_t(h2)], l = he.from[size_t(g2)];
  // The new diagonal's length in the two triangles unfolded flat about edge ij.
  const double ki = he.length[size_t(h2)], il = he.length[size_t(g1)];
  const double theta = angle_at_origin(he, h) + angle_at_origin(he, g1);
  const double kl = std::sqrt(std::max(ki * ki + il * il - 2.0 * ki * il * std::cos(theta), 0.0));
  // Old records of the four outer half-edges, then the two triangles rewritten in place:
  // (l->k, k->i, i->l) in h's slots and (k->l, l->j, j->k) in g's.
  struct Record {
    int from, twin;
    double length;
  };
  const int outer_old[4] = {h2, g1, g2, h1};
  Record rec[4];
  for (int q = 0; q < 4; ++q)
    rec[q] = {he.from[size_t(outer_old[q])], he.twin[size_t(outer_old[q])], he.length[size_t(outer_old[q])]};
  const int slot0 = h - h % 3, slot1 = g - g % 3;
  const int outer_new[4] = {slot0 + 1, slot0 + 2, slot1 + 1, slot1 + 2};
  auto renamed = [&](int old) {
    for (int q = 0; q < 4; ++q)
      if (outer_old[q] == old) return outer_new[q];
    return old;
  };
  he.from[size_t(slot0)] = l;
  he.from[size_t(slot1)] = k;
  he.length[size_t(slot0)] = he.length[size_t(slot1)] = kl;
  he.twin[size_t(slot0)] = slot1;
  he.twin[size_t(slot1)] = slot0;
  for (int q = 0; q < 4; ++q) {
    const int s = outer_new[q];
    he.from[size_t(s)] = rec[q].from;
    he.length[size_t(s)] = rec[q].length;
    he.twin[size_t(s)] = renamed(rec[q].twin);
  }
  for (int q = 0; q < 4; ++q) he.twin[size_t(he.twin[size_t(outer_new[q])])] = outer_new[q];
}

}  // namespace

CotangentWeights cotangent_weights(const NodeMat& x, const TriMat& tris, bool delaunay) {
  HalfEdges he = build_half_edges(x, tris);
  const int count = int(he.from.size());
  CotangentWeights out;
  if (delaunay) {
    // Flip edges whose opposite angles sum past pi until none is left (Lawson's algorithm on
    // the intrinsic metric; it ends, and every edge's weight is then >= 0).
    std::vector<int> stack;
    std::vector<char> queued(size_t(count), 0);
    for (int h = 0; h < count; ++h)
      if (he.twin[size_t(h)] > h) {
        stack.push_back(h);
        queued[size_t(h)] = 1;
      }
    const double tolerance = 1e-12;
    const long max_flips = 100L * count + 1000;  // far above what Lawson's algorithm needs
    while (!stack.empty() && out.flips < max_flips) {
      const int h = stack.back();
      stack.pop_back();
      queued[size_t(h)] = 0;
      const int g = he.twin[size_t(h)];
      if (g < 0) continue;
      if (cot_opposite(he, h) + cot_opposite(he, g) >= -tolerance) continue;
      flip(he, h);
      ++out.flips;
      const int slot0 = h - h % 3, slot1 = g - g % 3;
      for (const int s : {slot0 + 1, slot0 + 2, slot1 + 1, slot1 + 2}) {
        const int key = std::min(s, he.twin[size_t(s)]);
        if (key >= 0 && !queued[size_t(key)]) {
          queued[size_t(key)] = 1;
          stack.push_back(key);
        }
      }
    }
  }
  std::map<std::pair<int, int>, double> sum;
  for (int h = 0; h < count; ++h) {
    const int g = he.twin[size_t(h)];
    if (g < h) continue;  // each edge once (g < 0 only on an open surface: skipped)
    const int a = he.from[size_t(h)], b = he.from[size_t(g)];
    if (a == b) continue;
    sum[{std::min(a, b), std::max(a, b)}] += 0.5 * (cot_opposite(he, h) + cot_opposite(he, g));
  }
  out.edges.reserve(sum.size());
  out.weights.reserve(sum.size());
  for (const auto& [pair, w] : sum) {
    out.edges.push_back({pair.first, pair.second});
    out.weights.push_back(w);
  }
  return out;
}

}  // namespace vdm
