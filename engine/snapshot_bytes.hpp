#pragma once
// Reading and writing the raw bytes of state snapshots (engine/state_snapshot,
// engine/core/core_snapshot): integers, doubles, Eigen arrays with their shapes, and text, in
// this machine's byte order (a snapshot is read back by the same build). Reads check that the
// bytes are there and that an array has the shape the model gives it.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace vdm::snapshot {

// Raw bytes in this machine's order (a snapshot is read back by the same build).
class Writer {
 public:
  explicit Writer(std::string& out) : out_(out) {}
  // (an empty array's data() may be null: nothing is copied then)
  void bytes(const void* p, size_t n) {
    if (n > 0) out_.append(static_cast<const char*>(p), n);
  }
  void i64(std::int64_t v) { bytes(&v, sizeof v); }
  void f64(double v) { bytes(&v, sizeof v); }
  template <class M>
  void matrix(const M& x) {
    i64(x.rows());
    i64(x.cols());
    bytes(x.data(), sizeof(typename M::Scalar) * static_cast<size_t>(x.size()));
  }
  void text(const std::string& s) {
    i64(static_cast<std::int64_t>(s.size()));
    bytes(s.data(), s.size());
  }

 private:
  std::string& out_;
};

class Reader {
 public:
  Reader(std::string_view in, size_t& pos) : in_(in), pos_(pos) {}
  bool bytes(void* p, size_t n) {
    if (in_.size() - pos_ < n) return false;
    if (n == 0) return true;  // (an empty array's data() may be null)
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  bool i64(std::int64_t& v) { return bytes(&v, sizeof v); }
  bool f64(double& v) { return bytes(&v, sizeof v); }
  size_t left() const { return in_.size() - pos_; }  // bytes not read yet
  template <class T>
  bool integer(T& v) {
    std::int64_t x = 0;
    if (!i64(x)) return false;
    v = static_cast<T>(x);
    return true;
  }
  // The matrix must already have the snapshot's shape (sized for the model it is read into).
  template <class M>
  bool matrix(M& x) {
    std::int64_t r = 0, c = 0;
    if (!i64(r) || !i64(c) || r != x.rows() || c != x.cols()) return false;
    return bytes(x.data(), sizeof(typename M::Scalar) * static_cast<size_t>(x.size()));
  }
  // An array that may be saved with 0 rows (all zero; see StepWorkspace) or with n: sized
  // here when it has rows. `zero`: it had none (the array is then left as it is).
  template <class M>
  bool lazy_matrix(M& x, Eigen::Index n, bool& zero) {
    std::int64_t r = 0, c = 0;
    if (!i64(r) || !i64(c) || (r != 0 && r != n) || c != x.cols()) return false;
    zero = r == 0;
    if (zero) return true;
    x.resize(n, x.cols());
    return bytes(x.data(), sizeof(typename M::Scalar) * static_cast<size_t>(x.size()));
  }
  bool text(std::string& s) {
    std::int64_t n = 0;
    if (!i64(n) || n < 0 || static_cast<std::uint64_t>(n) > in_.size() - pos_) return false;
    s.assign(in_.data() + pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    return true;
  }

 private:
  std::string_view in_;
  size_t& pos_;
};

}  // namespace vdm::snapshot
