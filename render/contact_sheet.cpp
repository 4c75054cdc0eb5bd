#include "render/contact_sheet.hpp"

#include <algorithm>
#include <cmath>

#include "render/canvas.hpp"
#include "render/png_io.hpp"

namespace render {

std::vector<int> contact_sheet_frames(int frames, int count) {
  std::vector<int> out;
  if (frames <= 0 || count <= 0) return out;
  if (frames <= count || count == 1) {
    if (count == 1) return {0};
    for (int f = 0; f < frames; ++f) out.push_back(f);
    return out;
  }
  for (int i = 0; i < count; ++i) {
    const int f = static_cast<int>(std::lround(double(i) * (frames - 1) / (count - 1)));
    if (out.empty() || out.back() != f) out.push_back(f);
  }
  return out;
}

bool write_contact_sheet(const std::vector<Thumbnail>& thumbs, const std::string& title, const std::string& path,
                         int level, std::string& error) {
  if (thumbs.empty()) {
    error = path + ": no frames to show";
    return false;
  }
  const int tw = thumbs[0].image.width, th = thumbs[0].image.height;
  const int n = static_cast<int>(thumbs.size());
  const int cols = std::min(n, 4), rows = (n + cols - 1) / cols;
  const float body = 16.0f;
  size_t lines = 1;
  for (const Thumbnail& t : thumbs) lines = std::max(lines, size_t(std::count(t.label.begin(), t.label.end(), '\n')) + 1);
  const int gap = 10, label_h = 24 + 18 * int(lines - 1), title_h = 36;
  const int width = cols * tw + (cols + 1) * gap;
  const int height = title_h + rows * (th + label_h) + (rows + 1) * gap;
  auto canvas = Canvas::create(body, error);
  if (!canvas) return false;
  ImDrawList* dl = canvas->begin(width, height, 0.12f, 0.13f, 0.15f);
  ImGuiLayer& layer = canvas->layer();
  draw_text(dl, layer.font(FontRole::title), ImVec2(float(gap), 8.0f), IM_COL32(255, 255, 255, 255), title);
  for (int i = 0; i < n; ++i) {
    const int c = i % cols, r = i / cols;
    const float x = float(gap + c * (tw + gap)), y = float(title_h + gap + r * (th + label_h + gap));
    dl->AddImage(layer.texture(thumbs[i].image), ImVec2(x, y), ImVec2(x + tw, y + th));
    const std::string label = thumbs[i].label.empty() ? "frame " + std::to_string(thumbs[i].frame) : thumbs[i].label;
    draw_text(dl, layer.font(FontRole::body), ImVec2(x + 2, y + th + 3), IM_COL32(230, 230, 230, 255), label);
  }
  const Image sheet = canvas->end();
  return write_png(path, sheet, level, false, error);
}

}  // namespace render
