#pragma once
// Column sums in Eigen's order, taken in a pass that reads the entries itself.
#include "engine/simd2.hpp"

namespace vdm {

// A sum over the entries 0, 1, ... of a column (given in that order: four at a time as two
// pairs, then a last pair, then a last entry) in the order of Eigen 3.4's vectorised sum
// (Redux.h, linear vectorised traversal from index 0, as Eigen's dot() of two columns sums
// their products): pairs (4k, 4k + 1) into one partial sum, (4k + 2, 4k + 3) into another,
// the first of each taken as it is; then the two added, the last pair, the two lanes, the
// last entry.
class NodeSums {
 public:
  void add4(simd::V2 p0, simd::V2 p1) {
    if (count_ == 0) {
      s0_ = p0;
      s1_ = p1;
    } else {
      s0_ += p0;
      s1_ += p1;
    }
    count_ += 4;
  }
  void add2(simd::V2 p) {
    if (count_ == 0) s0_ = p;
    else tail_pair_ = p;
    count_ += 2;
    pair_ = true;
  }
  void add1(double v) {
    last_ = v;
    ++count_;
    single_ = true;
  }
  double total() const {
    if (count_ == 0) return 0.0;
    if (count_ == 1) return last_;
    simd::V2 s = s0_;
    if (count_ >= 4) {
      s += s1_;
      if (pair_) s += tail_pair_;
    }
    double r = s[0] + s[1];
    if (single_) r += last_;
    return r;
  }

 private:
  simd::V2 s0_ = {0.0, 0.0}, s1_ = {0.0, 0.0}, tail_pair_ = {0.0, 0.0};
  double last_ = 0.0;
  int count_ = 0;
  bool pair_ = false, single_ = false;
};

}  // namespace vdm
