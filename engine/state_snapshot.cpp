#include "engine/state_snapshot.hpp"

#include <cstdint>
#include <cstring>
#include <vector>

#include "engine/snapshot_bytes.hpp"
#include "engine/step_workspace.hpp"
#include "engine/warnings.hpp"

namespace vdm {
namespace {

using snapshot::Reader;
using snapshot::Writer;

// 2: the preconditioner's constrained set; 3: the structured solver's Galerkin step directions.
constexpr char kMagic[8] = {'V', 'D', 'M', 'S', 'T', 'A', 'T', '3'};

}  // namespace

void save_state(const TissueModel& m, const SimState& s, std::string& out) {
  const StepWorkspace& w = *s.work;
  // The solver's part first, so that the whole snapshot's size is known before it is written:
  // one allocation of the string instead of doublings that each copy it (at 40k nodes the
  // snapshot is about 30 MB, and a doubling held it twice for a moment).
  std::vector<double> warm;
  w.solver->save_warm_state(warm);
  size_t doubles = 0;
  for (const NodeMat* x : {&s.u, &s.x, &s.velocity, &s.area_vectors, &s.reaction, &s.strain, &s.stress, &w.x_refresh,
                           &w.last_springs, &w.force_last, &w.force_prev})
    doubles += size_t(x->size());
  doubles += size_t(s.node_volumes.size() + s.reaction_pressure.size() + w.pressure_last.size() + w.pressure_prev.size());
  size_t text = 0;
  for (const std::string& t : s.warnings) text += t.size() + 8;
  out.reserve(out.size() + 8 * (doubles + warm.size()) + size_t(w.last_mask.size()) + text + 512);
  Writer o(out);
  o.bytes(kMagic, sizeof kMagic);
  o.i64(m.n);
  o.i64(static_cast<std::int64_t>(m.solver.method));
  o.i64(s.step);
  o.f64(s.time);
  for (const NodeMat* x : {&s.u, &s.x, &s.velocity, &s.area_vectors, &s.reaction, &s.strain, &s.stress}) o.matrix(*x);
  o.matrix(s.node_volumes);
  o.matrix(s.reaction_pressure);
  o.f64(s.volume);
  o.f64(s.volume_rel_error);
  o.f64(s.pressure);
  o.i64(s.stats.total_refreshes);
  o.i64(s.stats.total_factorizations);
  o.i64(s.stats.total_fallbacks);
  o.i64(static_cast<std::int64_t>(s.warnings.size()));
  for (const std::string& t : s.warnings) o.text(t);
  // The engine's carry-over.
  o.matrix(w.x_refresh);
  o.i64(w.have_geometry);
  o.i64(w.matrix_dirty);
  o.i64(w.steps_since_refresh);
  o.matrix(w.last_mask);
  // Zero ones with 0 rows (as StepWorkspace keeps them).
  const NodeMat no_rows(0, 3);
  const Vec no_entries;
  o.matrix(w.last_springs);
  o.matrix(w.force_last_zero ? no_rows : w.force_last);
  o.matrix(w.force_prev_zero ? no_rows : w.force_prev);
  o.matrix(w.pressure_last_zero ? no_entries : w.pressure_last);
  o.matrix(w.pressure_prev_zero ? no_entries : w.pressure_prev);
  o.i64(static_cast<std::int64_t>(warm.size()));
  o.bytes(warm.data(), warm.size() * sizeof(double));
}

bool load_state(const TissueModel& m, std::string_view in, size_t& pos, SimState& s, std::string& error) {
  StepWorkspace& w = *s.work;
  Reader r(in, pos);
  auto fail = [&](const char* what) {
    error = std::string("state snapshot: ") + what;
    return false;
  };
  char magic[sizeof kMagic];
  if (!r.bytes(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0)
    return fail("not a snapshot (or of another version)");
  std::int64_t n = 0;
  if (!r.i64(n) || n != m.n) return fail("of a model with another number of nodes");
  std::int64_t method = 0;
  if (!r.i64(method) || method != static_cast<std::int64_t>(m.solver.method)) return fail("of another solver");
  if (!r.integer(s.step) || !r.f64(s.time)) return fail("truncated");
  for (NodeMat* x : {&s.u, &s.x, &s.velocity, &s.area_vectors, &s.reaction, &s.strain, &s.stress})
    if (!r.matrix(*x)) return fail("truncated or of another model");
  if (!r.matrix(s.node_volumes) || !r.matrix(s.reaction_pressure)) return fail("truncated or of another model");
  if (!r.f64(s.volume) || !r.f64(s.volume_rel_error) || !r.f64(s.pressure)) return fail("truncated");
  if (!r.integer(s.stats.total_refreshes) || !r.integer(s.stats.total_factorizations) ||
      !r.integer(s.stats.total_fallbacks))
    return fail("truncated");
  std::int64_t warnings = 0;
  if (!r.i64(warnings) || warnings < 0 || warnings > static_cast<std::int64_t>(kMaxWarnings)) return fail("bad warning count");
  s.warnings.clear();
  for (std::int64_t k = 0; k < warnings; ++k) {
    std::string t;
    if (!r.text(t)) return fail("truncated");
    s.warnings.push_back(std::move(t));
  }
  if (!r.matrix(w.x_refresh) || !r.integer(w.have_geometry) || !r.integer(w.matrix_dirty) ||
      !r.integer(w.steps_since_refresh) || !r.matrix(w.last_mask))
    return fail("truncated or of another model");
  bool springs_zero = false;
  if (!r.lazy_matrix(w.last_springs, m.n, springs_zero) || !r.lazy_matrix(w.force_last, m.n, w.force_last_zero) ||
      !r.lazy_matrix(w.force_prev, m.n, w.force_prev_zero) || !r.lazy_matrix(w.pressure_last, m.n, w.pressure_last_zero) ||
      !r.lazy_matrix(w.pressure_prev, m.n, w.pressure_prev_zero))
    return fail("truncated or of another model");
  if (springs_zero) w.last_springs.setZero();  // (sized or not: zero)
  std::int64_t count = 0;
  if (!r.i64(count) || count < 0 || static_cast<std::uint64_t>(count) > (in.size() - pos) / sizeof(double))
    return fail("truncated");
  std::vector<double> warm(static_cast<size_t>(count));
  r.bytes(warm.data(), warm.size() * sizeof(double));
  w.last_springs_any = !w.last_springs.isZero(0.0);
  w.input_remembered = false;
  s.failed = false;
  s.failure.clear();
  rebuild_matrices(m, s);
  if (!w.solver->load_warm_state(warm)) return fail("of another solver");
  return true;
}

}  // namespace vdm
