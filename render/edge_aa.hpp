#pragma once
// Edge anti-aliasing of an image rendered at one sample per pixel, on the CPU (render
// `antialias: edge`). A polygon's edge drawn without multisampling is a staircase: runs of
// pixels along a row (or column) whose neighbour across the run has the other side's colour,
// ending in one-pixel steps. The straight edge the staircase comes from passes through the
// midpoints of the steps; each pixel next to a run takes the other side's colour by the
// share of the pixel that this straight edge cuts off (a coverage estimate, the quantity
// multisampling measures with its samples). Pixels away from edges, and edges that stay on
// one row or column past the search distance (axis-aligned edges), are left unchanged.
//
// Deterministic: integer arithmetic on the colours, the result depends only on the input.
#include <cstdint>
#include <vector>

#include "render/image.hpp"

namespace render {

struct EdgeAaSettings {
  // Two neighbouring pixels are on either side of an edge when some colour channel differs
  // by more than this (0-255): soft shading and blurred shadows change by less per pixel.
  int threshold = 20;
  // How far (pixels) a run is followed each way to find its ends.
  int max_search = 24;
};

struct EdgeAaStats {
  long candidates = 0;  // pixels next to an edge
  long blended = 0;     // pixels whose colour changed
};

class EdgeSmoother {
 public:
  explicit EdgeSmoother(EdgeAaSettings settings = {}) : settings_(settings) {}
  // Smooths `image` in place (RGB; alpha is left as it is). Buffers are kept between calls.
  EdgeAaStats apply(Image& image);

 private:
  struct Change {
    std::uint32_t index;  // pixel index
    std::uint8_t rgb[3];
  };
  EdgeAaSettings settings_;
  std::vector<std::uint8_t> across_x_, across_y_;  // largest channel difference to the right / below
  std::vector<std::uint8_t> flags_;                  // one row's candidates
  std::vector<Change> changes_;
};

// Draws `layer` (premultiplied RGBA, e.g. a HUD drawn onto transparent black with
// (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) colour and (ONE, ONE_MINUS_SRC_ALPHA) alpha blending)
// over `image`, its top-left pixel at (x0, y0) of `image` (rows top first in both).
void composite_over(Image& image, const Image& layer, int x0, int y0);

}  // namespace render
