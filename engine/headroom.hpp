#pragma once
// Sizing arrays that follow the number of contacts without allocating at every new maximum:
// when one must grow it reserves twice the size asked, so that once warmed up by the largest
// contact (and somewhat beyond it) nothing is allocated.
#include <algorithm>
#include <vector>

namespace vdm {

template <class T>
void resize_with_headroom(std::vector<T>& v, size_t n) {
  if (n > v.capacity()) v.reserve(2 * n);
  v.resize(n);
}

// v sized c x c; room for (2c) x (2c) when it must grow.
template <class T>
void resize_square_with_headroom(std::vector<T>& v, size_t c) {
  if (c * c > v.capacity()) v.reserve(4 * c * c);
  v.resize(c * c);
}

template <class T>
void assign_with_headroom(std::vector<T>& v, size_t n, const T& value) {
  resize_with_headroom(v, n);
  std::fill(v.begin(), v.end(), value);
}

template <class T, class It>
void assign_with_headroom(std::vector<T>& v, It first, It last) {
  resize_with_headroom(v, static_cast<size_t>(std::distance(first, last)));
  std::copy(first, last, v.begin());
}

}  // namespace vdm
