#pragma once
// The tissue's surface detail: a smooth random field, periodic over a cube, sampled into a
// 3D texture. Each texel's RGBA8 holds the field's gradient (RGB, 0.5 + 0.5 g / |g|max) and the
// field (A, 0 to 1). The tissue shader reads it at the surface's rest position (so the pattern
// stays on the tissue as it deforms) at two scales: the coarse for colour variation, the fine
// to tilt the normal (fine bumps under a light). Seeded: the same texels on every run.
#include <cstdint>
#include <vector>

namespace render {

// n^3 texels (n a multiple of 16), x fastest; the field is value noise in three octaves, periodic
// over the cube.
std::vector<std::uint8_t> tissue_noise_texture(int n, std::uint32_t seed);

}  // namespace render
