#include "engine/core/core_snapshot.hpp"

#include <cstdint>
#include <cstring>
#include <vector>

#include "engine/core/core_workspace.hpp"
#include "engine/snapshot_bytes.hpp"
#include "engine/warnings.hpp"

namespace vdm::core {
namespace {

using snapshot::Reader;
using snapshot::Writer;

constexpr char kCoreMagic[8] = {'V', 'D', 'M', 'C', 'O', 'R', 'E', '1'};

static_assert(sizeof(int) == sizeof(std::int32_t), "node lists are saved as 32-bit integers");

void write_ints(Writer& o, const std::vector<int>& v) {
  o.i64(static_cast<std::int64_t>(v.size()));
  o.bytes(v.data(), sizeof(int) * v.size());
}

// A list of at most `most` integers, each in [0, bound).
bool read_ints(Reader& r, std::vector<int>& v, std::int64_t most, int bound) {
  std::int64_t n = 0;
  if (!r.i64(n) || n < 0 || n > most) return false;
  v.resize(static_cast<size_t>(n));
  if (!r.bytes(v.data(), sizeof(int) * v.size())) return false;
  for (int x : v)
    if (x < 0 || x >= bound) return false;
  return true;
}

// A flag saved as 0 or 1.
bool read_flag(Reader& r, bool& flag) {
  std::int64_t x = -1;
  if (!r.i64(x) || (x != 0 && x != 1)) return false;
  flag = x == 1;
  return true;
}

// The displacements, velocities, where the step started, the last static motion, the
// results and the warnings.
void save_motion(const CoreState& s, Writer& o) {
  for (const NodeMat* x : {&s.u, &s.v, &s.velocity, &s.u_start, &s.v_start, &s.velocity_start, &s.u_motion,
                           &s.v_motion, &s.reaction})
    o.matrix(*x);
  o.i64(s.rewound);
  o.f64(s.pressure);
  o.f64(s.volume);
  o.f64(s.volume_rel_error);
  o.i64(static_cast<std::int64_t>(s.warnings.size()));
  for (const std::string& t : s.warnings) o.text(t);
}

bool load_motion(Reader& r, CoreState& s) {
  for (NodeMat* x : {&s.u, &s.v, &s.velocity, &s.u_start, &s.v_start, &s.velocity_start, &s.u_motion, &s.v_motion,
                     &s.reaction})
    if (!r.matrix(*x)) return false;
  std::int64_t warnings = -1;
  if (!read_flag(r, s.rewound) || !r.f64(s.pressure) || !r.f64(s.volume) || !r.f64(s.volume_rel_error) ||
      !r.i64(warnings) || warnings < 0 || warnings > static_cast<std::int64_t>(kMaxWarnings))
    return false;
  s.warnings.assign(static_cast<size_t>(warnings), std::string());
  for (std::string& t : s.warnings)
    if (!r.text(t)) return false;
  return true;
}

// The tets' last rotations (x, y, z, w per tet).
void save_rotations(const CoreWorkspace& w, Writer& o) {
  o.i64(static_cast<std::int64_t>(w.quaternion.size()));
  for (const Eigen::Quaterniond& q : w.quaternion) o.bytes(q.coeffs().data(), 4 * sizeof(double));
}

bool load_rotations(Reader& r, CoreWorkspace& w) {
  std::int64_t n = -1;
  if (!r.i64(n) || n != static_cast<std::int64_t>(w.quaternion.size())) return false;
  for (Eigen::Quaterniond& q : w.quaternion)
    if (!r.bytes(q.coeffs().data(), 4 * sizeof(double))) return false;
  return true;
}

// Which entries each factor slot was made for and which axis uses which; per slot, the lattice
// nodes of its columns and the groups they were solved in.
void save_factors(const CoreWorkspace& w, Writer& o) {
  o.matrix(w.factored_mask);
  o.matrix(w.chol_mask);
  for (int k = 0; k < 3; ++k) {
    o.i64(w.factored[k]);
    o.i64(w.slot[k]);
    o.i64(w.chol_ok[k]);
    write_ints(o, w.columns[k].node);
    write_ints(o, w.columns[k].batch);
  }
}

bool flags_only(const FlagMat& f) { return (f.array() <= 1).all(); }

// The saved columns of a slot: distinct lattice nodes, in groups that add up to them, and
// only on a slot with a factor.
bool columns_fit(const CoreModel& m, const std::vector<int>& node, const std::vector<int>& batch, bool factor) {
  if (!node.empty() && !factor) return false;
  std::vector<char> seen(static_cast<size_t>(m.ng), 0);
  for (int j : node) {
    if (seen[static_cast<size_t>(j)]) return false;
    seen[static_cast<size_t>(j)] = 1;
  }
  size_t sum = 0;
  for (int b : batch) {
    if (b <= 0) return false;
    sum += static_cast<size_t>(b);
  }
  return sum == node.size();
}

// Reads what save_factors() wrote; `node` and `batch`: each slot's columns, solved once the
// factors are made again.
bool load_factors(const CoreModel& m, Reader& r, CoreWorkspace& w, std::vector<int> (&node)[3],
                  std::vector<int> (&batch)[3]) {
  if (!r.matrix(w.factored_mask) || !r.matrix(w.chol_mask) || !flags_only(w.factored_mask) ||
      !flags_only(w.chol_mask))
    return false;
  for (int k = 0; k < 3; ++k) {
    std::int64_t slot = -1;
    if (!read_flag(r, w.factored[k]) || !r.i64(slot) || slot < 0 || slot > k || !read_flag(r, w.chol_ok[k]))
      return false;
    w.slot[k] = static_cast<int>(slot);
    if (!read_ints(r, node[k], m.ng, m.ng) || !read_ints(r, batch[k], m.ng, m.ng + 1) ||
        !columns_fit(m, node[k], batch[k], w.chol_ok[k]))
      return false;
  }
  // An axis shares the factor of an earlier axis that has its own.
  for (int k = 0; k < 3; ++k)
    if (w.slot[w.slot[k]] != w.slot[k]) return false;
  return true;
}

// Each slot's matrix built and factorised again for the entries it was made for, and its
// columns solved again in their groups.
bool rebuild_factors(const CoreModel& m, CoreWorkspace& w, const std::vector<int> (&node)[3],
                     const std::vector<int> (&batch)[3]) {
  for (int k = 0; k < 3; ++k) {
    if (!w.chol_ok[k]) continue;
    factorize_slot(m, k, w);
    if (!w.chol_ok[k]) return false;
    LatticeColumns& c = w.columns[k];
    c.slot.assign(static_cast<size_t>(m.ng), -1);
    size_t next = 0;
    for (int b : batch[k]) {
      const int before = c.count;
      for (int q = 0; q < b; ++q, ++next) {
        const int j = node[k][next];
        c.slot[static_cast<size_t>(j)] = c.count++;
        c.node.push_back(j);
      }
      solve_columns(m, k, before, w);
    }
  }
  return true;
}

// The held entries, and their compliance when it was factorised.
void save_held(const HeldEntries& H, Writer& o) {
  write_ints(o, H.node);
  write_ints(o, H.axis);
  o.i64(H.factored);
  if (H.factored) o.matrix(H.C0);
}

bool load_held(const CoreModel& m, Reader& r, HeldEntries& H) {
  bool factored = false;
  if (!read_ints(r, H.node, 3 * std::int64_t{m.ns}, m.ns) || !read_ints(r, H.axis, 3 * std::int64_t{m.ns}, 3) ||
      H.node.size() != H.axis.size() || !read_flag(r, factored))
    return false;
  H.factored = false;
  if (!factored) return true;
  // (a count that the bytes left cannot hold is refused before C0 is sized to it)
  const size_t n = H.node.size();
  if (n == 0 || r.left() / sizeof(double) / n < n) return false;
  H.C0.resize(H.size(), H.size());
  return r.matrix(H.C0) && factor_held_entries(H);
}

}  // namespace

void save_core_state(const CoreModel& m, const CoreState& s, std::string& out) {
  const CoreWorkspace& w = *s.work;
  Writer o(out);
  o.bytes(kCoreMagic, sizeof kCoreMagic);
  o.i64(m.ns);
  o.i64(m.ng);
  o.i64(m.cubes.rows());
  o.f64(m.h);
  o.f64(m.rest_volume);
  save_motion(s, o);
  save_rotations(w, o);
  save_factors(w, o);
  save_held(w.held, o);
}

bool load_core_state(const CoreModel& m, std::string_view in, size_t& pos, CoreState& s, std::string& error) {
  CoreWorkspace& w = *s.work;
  Reader r(in, pos);
  auto fail = [&](const char* what) {
    error = std::string("state snapshot: the elastic core's ") + what;
    return false;
  };
  char magic[sizeof kCoreMagic];
  if (!r.bytes(magic, sizeof magic) || std::memcmp(magic, kCoreMagic, sizeof magic) != 0)
    return fail("state is missing (or of another version)");
  std::int64_t ns = 0, ng = 0, cubes = 0;
  double h = 0, volume = 0;
  if (!r.i64(ns) || !r.i64(ng) || !r.i64(cubes) || !r.f64(h) || !r.f64(volume)) return fail("state is truncated");
  if (ns != m.ns || ng != m.ng || cubes != m.cubes.rows() || h != m.h || volume != m.rest_volume)
    return fail("state is of another lattice (organ mesh, cell size or placement)");
  if (!load_motion(r, s) || !load_rotations(r, w)) return fail("state is truncated or damaged");
  std::vector<int> node[3], batch[3];
  if (!load_factors(m, r, w, node, batch)) return fail("factors are truncated or damaged");
  if (!rebuild_factors(m, w, node, batch)) return fail("lattice matrix does not factorise again");
  if (!load_held(m, r, w.held)) return fail("held entries are truncated or damaged");
  return true;
}

CoreCarry core_carry(const CoreState& s) {
  const CoreWorkspace& w = *s.work;
  CoreCarry c;
  c.held = w.held.size();
  c.held_factored = w.held.factored;
  c.factored = w.factored_mask;
  for (int k = 0; k < 3; ++k) {
    c.factors += w.chol_ok[k];
    c.columns += w.columns[k].count;
    c.column_solves += static_cast<int>(w.columns[k].batch.size());
  }
  return c;
}

}  // namespace vdm::core
