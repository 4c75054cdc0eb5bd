#include "render/edge_aa.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace render {
namespace {

// out[p] = the largest difference of the R, G, B channels of pixels a[p] and b[p] (RGBA).
void pixel_differences(const std::uint8_t* a, const std::uint8_t* b, std::uint8_t* out, size_t pixels) {
  size_t p = 0;
#if defined(__SSE2__)
  // Eight pixels at a time: byte differences, the largest of each pixel's first three bytes,
  // packed to bytes.
  const __m128i low_byte = _mm_set1_epi32(0xff);
  auto largest = [&](__m128i x, __m128i y) {
    const __m128i d = _mm_or_si128(_mm_subs_epu8(x, y), _mm_subs_epu8(y, x));
    const __m128i m = _mm_max_epu8(d, _mm_max_epu8(_mm_srli_epi32(d, 8), _mm_srli_epi32(d, 16)));
    return _mm_and_si128(m, low_byte);
  };
  for (; p + 8 <= pixels; p += 8) {
    const __m128i* pa = reinterpret_cast<const __m128i*>(a + 4 * p);
    const __m128i* pb = reinterpret_cast<const __m128i*>(b + 4 * p);
    const __m128i m0 = largest(_mm_loadu_si128(pa), _mm_loadu_si128(pb));
    const __m128i m1 = largest(_mm_loadu_si128(pa + 1), _mm_loadu_si128(pb + 1));
    const __m128i words = _mm_packs_epi32(m0, m1);  // 0-255 in 16 bits
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + p), _mm_packus_epi16(words, words));
  }
#endif
  for (; p < pixels; ++p) {
    const std::uint8_t* x = a + 4 * p;
    const std::uint8_t* y = b + 4 * p;
    const int d0 = std::abs(int(x[0]) - int(y[0])), d1 = std::abs(int(x[1]) - int(y[1])), d2 = std::abs(int(x[2]) - int(y[2]));
    out[p] = static_cast<std::uint8_t>(std::max(d0, std::max(d1, d2)));
  }
}

// How a run ends: `toward` when the pixel next to the run's last one, in the pixel's own row,
// has the colour of the other side (the edge steps into this row: it cuts into the pixels
// near that end), `away` when the edge steps the other way (it cuts into the other row),
// `none` when no end was found (image border, or farther than the search).
enum class EndKind { none, toward, away };
struct RunEnd {
  int distance;  // from the pixel to the first pixel past the run
  EndKind kind;
};

// The share of a pixel cut off by a straight edge that is half a pixel into the pixel's row
// at a step and falls by `slope` per pixel along the run, for the pixel spanning [t0, t0 + 1]
// from the step: the integral of max(0, 0.5 - slope t) over the pixel.
double cut_share(double t0, double slope) {
  const double h0 = 0.5 - slope * t0, h1 = h0 - slope;
  if (h1 >= 0) return 0.5 * (h0 + h1);
  if (h0 <= 0) return 0.0;
  return h0 * h0 / (2.0 * slope);
}

// A run between two steps the same way is the flattest part of a curved edge (the top of a
// circle): the edge is taken as the parabola through both steps' midpoints (half a pixel into
// the row whose colour steps in) that keeps the areas on either side as the staircase has
// them, h(t) = 0.5 - 3 t (L - t) / L^2 for a run of length L: into that row near the ends,
// a quarter of a pixel into the other row at the middle. The share of the pixel spanning
// [t0, t0 + 1] that it cuts off on the side `sign` (+1: h > 0; -1: h < 0).
double arc_share(double t0, double length, int sign) {
  const int n = 8;  // midpoint rule: the parabola's curvature over one pixel is small
  double sum = 0;
  for (int k = 0; k < n; ++k) {
    const double t = t0 + (k + 0.5) / n;
    const double h = 0.5 - 3.0 * t * (length - t) / (length * length);
    sum += std::min(1.0, std::max(0.0, sign * h));
  }
  return sum / n;
}

}  // namespace

EdgeAaStats EdgeSmoother::apply(Image& image) {
  EdgeAaStats stats;
  const int W = image.width, H = image.height;
  if (W < 2 || H < 2) return stats;
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  const std::uint8_t* px = image.rgba.data();
  // The largest channel difference of each pixel to its right and lower neighbours.
  across_x_.resize(n);
  across_y_.resize(n);
  for (int y = 0; y < H; ++y) across_x_[static_cast<size_t>(y) * W + (W - 1)] = 0;  // no right neighbour
  std::memset(across_y_.data() + (n - W), 0, static_cast<size_t>(W));                // no lower neighbour
  flags_.resize(static_cast<size_t>(W) + 8);
  for (int y = 0; y < H; ++y) {
    const size_t row = static_cast<size_t>(y) * W;
    pixel_differences(px + 4 * row, px + 4 * row + 4, across_x_.data() + row, static_cast<size_t>(W - 1));
    if (y + 1 < H) pixel_differences(px + 4 * row, px + 4 * (row + W), across_y_.data() + row, static_cast<size_t>(W));
  }

  const int T = settings_.threshold, K = settings_.max_search;
  const std::uint8_t* ax = across_x_.data();
  const std::uint8_t* ay = across_y_.data();
  changes_.clear();
  std::uint8_t* flag = flags_.data();
  for (int y = 0; y < H; ++y) {
    // Candidates of this row: a pixel with an edge on any of its four sides.
    const size_t row = static_cast<size_t>(y) * W;
    const std::uint8_t* above = y > 0 ? ay + row - W : ay + row;  // row 0: its own lower edges again
    for (int x = 0; x < W; ++x) {
      const std::uint8_t m = std::max(std::max(ax[row + x], ay[row + x]), above[x]);
      flag[x] = m > T ? 1 : 0;
    }
    for (int x = 1; x < W; ++x) flag[x] = static_cast<std::uint8_t>(flag[x] | (ax[row + x - 1] > T ? 1 : 0));
    std::memset(flag + W, 0, 8);
    for (int x = 0; x < W; ++x) {
      if ((x & 7) == 0) {  // skip eight pixels without an edge at once
        std::uint64_t word;
        std::memcpy(&word, flag + x, 8);
        if (word == 0) {
          x += 7;
          continue;
        }
      }
      if (!flag[x]) continue;
      const size_t i = row + x;
      const int left = x > 0 ? ax[i - 1] : 0, right = ax[i];
      const int up = y > 0 ? ay[i - W] : 0, down = ay[i];
      ++stats.candidates;
      // The share of the pixel that the edge between it and its neighbour `across` (a row
      // above or below: a horizontal edge; a column left or right: a vertical one) cuts off.
      auto share_of = [&](bool horizontal, long across) -> double {
        const long along = horizontal ? 1 : W;
        const int pos = horizontal ? x : y, limit = horizontal ? W : H;
        const std::uint8_t* cp = px + 4 * i;
        const std::uint8_t* cq = px + 4 * (long(i) + across);
        const int dq0 = int(cq[0]) - cp[0], dq1 = int(cq[1]) - cp[1], dq2 = int(cq[2]) - cp[2];
        const int den = dq0 * dq0 + dq1 * dq1 + dq2 * dq2;
        // Whether colour c is nearer q's than p's along the colour difference across the edge.
        auto like_q = [&](const std::uint8_t* c) {
          return 2 * ((int(c[0]) - cp[0]) * dq0 + (int(c[1]) - cp[1]) * dq1 + (int(c[2]) - cp[2]) * dq2) > den;
        };
        auto walk = [&](int dir) -> RunEnd {
          for (int k = 1; k <= K; ++k) {
            const int c = pos + dir * k;
            if (c < 0 || c >= limit) return {k, EndKind::none};
            const std::uint8_t* a = px + 4 * (long(i) + dir * k * along);
            const bool a_q = like_q(a), b_q = like_q(a + 4 * across);
            if (!a_q && b_q) continue;  // the edge goes on
            if (!b_q) {
            if (a_q) return {k, EndKind::none};  // the sides swap: a crossing
            // This side's colour in the other row: a step if the edge goes on one row farther
            // on, a corner of the other side's region if not.
            const int farther = (horizontal ? y : x) + 2 * (across > 0 ? 1 : -1);
            if (farther >= 0 && farther < (horizontal ? H : W) && !like_q(a + 8 * across)) return {k, EndKind::none};
            return {k, EndKind::away};
          }
            // The other side's colour in this row: a step if the edge goes on one row farther
            // from the other side, a corner (an edge turning across the run) if not.
            const int beyond = (horizontal ? y : x) - (across > 0 ? 1 : -1);
            if (beyond >= 0 && beyond < (horizontal ? H : W) && like_q(a - 4 * across)) return {k, EndKind::none};
            return {k, EndKind::toward};
          }
          return {K + 1, EndKind::none};
        };
        const RunEnd ends[2] = {walk(-1), walk(+1)};
        const int length = ends[0].distance + ends[1].distance - 1;
        if (ends[0].kind == ends[1].kind && ends[0].kind != EndKind::none)  // two steps the same way
          return arc_share(ends[0].distance - 1, length, ends[0].kind == EndKind::toward ? 1 : -1);
        // Otherwise a straight edge from half a pixel into this row at a step to half a pixel
        // into the other row at the run's other end (or past the search).
        double share = 0;
        for (const RunEnd& e : ends)
          if (e.kind == EndKind::toward) share = std::max(share, cut_share(e.distance - 1, 1.0 / length));
        return share;
      };
      // The edge's direction: the stronger of the differences between rows (a horizontal
      // edge) and between columns (a vertical one) over the 3 x 3 neighbourhood; the neighbour
      // across it, the one that differs more. (Taking both directions at a diagonal staircase
      // measured worse against supersampling.)
      int between_rows = 0, between_columns = 0;
      for (int d = -1; d <= 1; ++d) {
        if (x + d >= 0 && x + d < W) between_rows += (y > 0 ? ay[i - W + d] : 0) + ay[i + d];
        if (y + d >= 0 && y + d < H) {
          const size_t j = static_cast<size_t>(y + d) * W + x;
          between_columns += (x > 0 ? ax[j - 1] : 0) + ax[j];
        }
      }
      const bool horizontal = between_rows >= between_columns;
      if (horizontal ? std::max(up, down) <= T : std::max(left, right) <= T) continue;
      const long across = horizontal ? (up > down ? -long(W) : long(W)) : (left > right ? -1 : 1);
      const int w = static_cast<int>(share_of(horizontal, across) * 256.0 + 0.5);
      if (w <= 0) continue;
      const std::uint8_t* cp = px + 4 * i;
      const std::uint8_t* cq = px + 4 * (long(i) + across);
      Change ch;
      ch.index = static_cast<std::uint32_t>(i);
      for (int k = 0; k < 3; ++k) ch.rgb[k] = static_cast<std::uint8_t>((cp[k] * (256 - w) + cq[k] * w + 128) >> 8);
      changes_.push_back(ch);
    }
  }
  for (const Change& ch : changes_) {
    std::uint8_t* p = image.rgba.data() + 4 * static_cast<size_t>(ch.index);
    p[0] = ch.rgb[0];
    p[1] = ch.rgb[1];
    p[2] = ch.rgb[2];
  }
  stats.blended = static_cast<long>(changes_.size());
  return stats;
}

void composite_over(Image& image, const Image& layer, int x0, int y0) {
  for (int y = 0; y < layer.height; ++y) {
    if (y0 + y < 0 || y0 + y >= image.height) continue;
    for (int x = 0; x < layer.width; ++x) {
      if (x0 + x < 0 || x0 + x >= image.width) continue;
      const std::uint8_t* s = layer.pixel(x, y);
      if (s[3] == 0) continue;
      std::uint8_t* d = image.pixel(x0 + x, y0 + y);
      const int keep = 255 - s[3];
      for (int k = 0; k < 3; ++k) d[k] = static_cast<std::uint8_t>(std::min(255, s[k] + (d[k] * keep + 127) / 255));
    }
  }
}

}  // namespace render
