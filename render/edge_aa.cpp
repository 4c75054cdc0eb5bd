#include "render/edge_aa.hpp"

#include <algorithm>
#include <cstdlib>

namespace render {
namespace {

// Largest difference of the R, G, B channels of two pixels.
inline std::uint8_t channel_difference(const std::uint8_t* a, const std::uint8_t* b) {
  const int d0 = std::abs(int(a[0]) - int(b[0])), d1 = std::abs(int(a[1]) - int(b[1])), d2 = std::abs(int(a[2]) - int(b[2]));
  return static_cast<std::uint8_t>(std::max(d0, std::max(d1, d2)));
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

}  // namespace

EdgeAaStats EdgeSmoother::apply(Image& image) {
  EdgeAaStats stats;
  const int W = image.width, H = image.height;
  if (W < 2 || H < 2) return stats;
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  const std::uint8_t* px = image.rgba.data();
  across_x_.assign(n, 0);
  across_y_.assign(n, 0);
  for (int y = 0; y < H; ++y) {
    const size_t row = static_cast<size_t>(y) * W;
    for (int x = 0; x + 1 < W; ++x) across_x_[row + x] = channel_difference(px + 4 * (row + x), px + 4 * (row + x + 1));
    if (y + 1 < H)
      for (int x = 0; x < W; ++x) across_y_[row + x] = channel_difference(px + 4 * (row + x), px + 4 * (row + x + W));
  }

  const int T = settings_.threshold, K = settings_.max_search;
  const std::uint8_t* ax = across_x_.data();
  const std::uint8_t* ay = across_y_.data();
  changes_.clear();
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const size_t i = static_cast<size_t>(y) * W + x;
      const int left = x > 0 ? ax[i - 1] : 0, right = ax[i];
      const int up = y > 0 ? ay[i - W] : 0, down = ay[i];
      if (std::max(std::max(left, right), std::max(up, down)) <= T) continue;
      ++stats.candidates;
      // The edge's direction: the stronger of the differences between rows (a horizontal
      // edge) and between columns (a vertical one) over the 3 x 3 neighbourhood.
      int between_rows = 0, between_columns = 0;
      for (int d = -1; d <= 1; ++d) {
        if (x + d >= 0 && x + d < W) between_rows += (y > 0 ? ay[i - W + d] : 0) + ay[i + d];
        if (y + d >= 0 && y + d < H) {
          const size_t j = static_cast<size_t>(y + d) * W + x;
          between_columns += (x > 0 ? ax[j - 1] : 0) + ax[j];
        }
      }
      const bool horizontal = between_rows >= between_columns;
      // The neighbour across the edge (the larger difference), and the step along it.
      long across, along;
      int pos, limit;
      if (horizontal) {
        if (std::max(up, down) <= T) continue;
        across = up > down ? -long(W) : long(W);
        along = 1;
        pos = x;
        limit = W;
      } else {
        if (std::max(left, right) <= T) continue;
        across = left > right ? -1 : 1;
        along = W;
        pos = y;
        limit = H;
      }
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
          return {k, a_q ? EndKind::toward : EndKind::away};
        }
        return {K + 1, EndKind::none};
      };
      const RunEnd ends[2] = {walk(-1), walk(+1)};
      // The straight edge falls from half a pixel at a step to nothing at the run's middle (a
      // run between two steps the same way) or to half a pixel the other way at its other end:
      // either way by one pixel over the run's length.
      const int length = ends[0].distance + ends[1].distance - 1;
      const double slope = 1.0 / length;
      double share = 0;
      for (const RunEnd& e : ends)
        if (e.kind == EndKind::toward) share = std::max(share, cut_share(e.distance - 1, slope));
      const int w = static_cast<int>(share * 256.0 + 0.5);
      if (w <= 0) continue;
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
