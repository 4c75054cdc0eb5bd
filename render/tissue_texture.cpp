#include "render/tissue_texture.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace render {
namespace {

// Random values from mt19937's raw output (its sequence is fixed by the standard; the
// standard library's distributions are not), in [0, 1).
double draw_unit(std::mt19937& g) { return double(g()) / 4294967296.0; }

// Quintic fade: the interpolated field's gradient is continuous across lattice cells.
double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

// One octave of value noise over the n^3 texels: random values on a periodic lattice of
// `cells`^3 (n a multiple of cells), interpolated with the quintic fade, added to `field`
// times `amplitude`.
void add_value_noise(std::vector<double>& field, int n, int cells, double amplitude, std::mt19937& g) {
  std::vector<double> lattice(size_t(cells) * size_t(cells) * size_t(cells));
  for (double& v : lattice) v = 2 * draw_unit(g) - 1;
  auto at = [&](int x, int y, int z) {
    x %= cells;
    y %= cells;
    z %= cells;
    return lattice[(size_t(z) * size_t(cells) + size_t(y)) * size_t(cells) + size_t(x)];
  };
  const int step = n / cells;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int cx = x / step, cy = y / step, cz = z / step;
        const double fx = fade(double(x % step) / step), fy = fade(double(y % step) / step),
                     fz = fade(double(z % step) / step);
        double v = 0;
        for (int k = 0; k < 8; ++k) {
          const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
          const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
          v += w * at(cx + dx, cy + dy, cz + dz);
        }
        field[(size_t(z) * size_t(n) + size_t(y)) * size_t(n) + size_t(x)] += amplitude * v;
      }
}

}  // namespace

std::vector<std::uint8_t> tissue_noise_texture(int n, std::uint32_t seed) {
  std::mt19937 g(seed);
  const size_t count = size_t(n) * size_t(n) * size_t(n);
  std::vector<double> field(count, 0.0);
  // Three octaves, each half the size and amplitude of the one before.
  for (int cells = 4, octave = 0; octave < 3 && cells <= n; ++octave, cells *= 2)
    add_value_noise(field, n, cells, 1.0 / (1 << octave), g);
  auto index = [n](int x, int y, int z) {
    x = (x + n) % n;
    y = (y + n) % n;
    z = (z + n) % n;
    return (size_t(z) * size_t(n) + size_t(y)) * size_t(n) + size_t(x);
  };
  double lo = 1e30, hi = -1e30, gmax = 0;
  std::vector<double> grad(3 * count);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t i = index(x, y, z);
        // Central differences across the periodic texel grid.
        grad[3 * i] = 0.5 * (field[index(x + 1, y, z)] - field[index(x - 1, y, z)]);
        grad[3 * i + 1] = 0.5 * (field[index(x, y + 1, z)] - field[index(x, y - 1, z)]);
        grad[3 * i + 2] = 0.5 * (field[index(x, y, z + 1)] - field[index(x, y, z - 1)]);
        gmax = std::max(gmax, std::sqrt(grad[3 * i] * grad[3 * i] + grad[3 * i + 1] * grad[3 * i + 1] +
                                        grad[3 * i + 2] * grad[3 * i + 2]));
        lo = std::min(lo, field[i]);
        hi = std::max(hi, field[i]);
      }
  auto byte = [](double v) { return std::uint8_t(std::clamp(std::lround(v * 255.0), 0L, 255L)); };
  std::vector<std::uint8_t> out(4 * count);
  for (size_t i = 0; i < count; ++i) {
    for (int c = 0; c < 3; ++c) out[4 * i + size_t(c)] = byte(0.5 + 0.5 * grad[3 * i + size_t(c)] / std::max(gmax, 1e-30));
    out[4 * i + 3] = byte((field[i] - lo) / std::max(hi - lo, 1e-30));
  }
  return out;
}

}  // namespace render
