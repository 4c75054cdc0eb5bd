#include "render/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "render/canvas.hpp"
#include "render/number_format.hpp"
#include "render/png_io.hpp"

namespace render {
namespace {

// Okabe and Ito's colour-blind-safe palette (then a grey and a tenth colour).
const ImU32 kPalette[] = {IM_COL32(0, 114, 178, 255),  IM_COL32(213, 94, 0, 255),   IM_COL32(0, 158, 115, 255),
                          IM_COL32(204, 121, 167, 255), IM_COL32(230, 159, 0, 255),  IM_COL32(86, 180, 233, 255),
                          IM_COL32(0, 0, 0, 255),       IM_COL32(240, 228, 66, 255),
                          IM_COL32(140, 140, 140, 255),   // and a neutral grey (index 8)
                          IM_COL32(136, 34, 85, 255)};    // and Tol's wine (index 9)
constexpr size_t kColours = sizeof(kPalette) / sizeof(kPalette[0]);

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool valid() const { return lo <= hi; }
};

double axis_value(double v, bool log) { return log ? (v > 0 ? std::log10(v) : std::nan("")) : v; }

// Ticks in axis space: 1-2-5 steps, or whole decades on a log axis.
std::vector<double> ticks_for(double lo, double hi, bool log) {
  if (!log) return nice_ticks(lo, hi, 5);
  std::vector<double> t;
  const double step = std::max(1.0, std::ceil((std::floor(hi) - std::ceil(lo)) / 6.0));
  for (double d = std::ceil(lo); d <= hi + 1e-9; d += step) t.push_back(d);
  return t;
}

std::string tick_label(double v, bool log) {
  if (!log) return format_number(v, 4);
  // Decades from 0.001 to 10000 written out (100, not 1e+02).
  const long decade = std::lround(v);
  if (decade >= -3 && decade <= 4) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decade < 0 ? static_cast<int>(-decade) : 0, std::pow(10.0, decade));
    return buf;
  }
  return format_number(std::pow(10.0, v), 2);
}

void draw_panel(ImDrawList* dl, ImGuiLayer& layer, const Panel& p, float x0, float y0, float w, float h) {
  ImFont* body = layer.font(FontRole::body);
  ImFont* small = layer.font(FontRole::small);
  ImFont* title = layer.font(FontRole::title);
  const ImU32 ink = IM_COL32(30, 30, 30, 255), grid = IM_COL32(225, 225, 225, 255);
  // Data ranges in axis space.
  Range rx, ry;
  for (const Series& s : p.series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      const double ax = axis_value(s.x[i], p.log_x), ay = axis_value(s.y[i], p.log_y);
      if (std::isfinite(ax) && std::isfinite(ay)) {
        rx.add(ax);
        ry.add(ay);
      }
    }
  if (!rx.valid()) rx = {0, 1};
  if (!ry.valid()) ry = {0, 1};
  auto pad = [](Range& r, bool log) {
    if (r.hi - r.lo < 1e-12 * std::max(1.0, std::abs(r.hi))) {
      r.lo -= log ? 0.5 : std::max(1e-12, std::abs(r.lo) * 0.1 + 1e-12);
      r.hi += log ? 0.5 : std::max(1e-12, std::abs(r.hi) * 0.1 + 1e-12);
    }
    const double m = 0.05 * (r.hi - r.lo);
    r.lo -= m;
    r.hi += m;
  };
  pad(rx, p.log_x);
  pad(ry, p.log_y);
  const std::vector<double> xt = ticks_for(rx.lo, rx.hi, p.log_x), yt = ticks_for(ry.lo, ry.hi, p.log_y);
  float label_w = 0;
  for (double v : yt) label_w = std::max(label_w, text_size(small, tick_label(v, p.log_y)).x);
  // Plot area.
  const float fs = body->FontSize;
  const float left = x0 + label_w + fs * 1.0f, right = x0 + w - fs * 0.8f;
  const float top = y0 + title->FontSize * 1.6f + fs * 1.3f, bottom = y0 + h - fs * 2.8f;
  auto sx = [&](double v) { return float(left + (v - rx.lo) / (rx.hi - rx.lo) * (right - left)); };
  auto sy = [&](double v) { return float(bottom - (v - ry.lo) / (ry.hi - ry.lo) * (bottom - top)); };
  draw_text(dl, title, ImVec2(x0 + fs * 0.5f, y0 + fs * 0.3f), ink, p.title);
  draw_text(dl, body, ImVec2(x0 + fs * 0.5f, top - fs * 1.35f), ink, p.y_label);
  const ImVec2 xl = text_size(body, p.x_label);
  draw_text(dl, body, ImVec2((left + right - xl.x) * 0.5f, bottom + fs * 1.5f), ink, p.x_label);
  dl->AddRectFilled(ImVec2(left, top), ImVec2(right, bottom), IM_COL32(255, 255, 255, 255));
  for (double v : xt) {
    const float x = sx(v);
    dl->AddLine(ImVec2(x, top), ImVec2(x, bottom), grid, 1.0f);
    dl->AddLine(ImVec2(x, bottom), ImVec2(x, bottom + fs * 0.3f), ink, 1.0f);
    const std::string t = tick_label(v, p.log_x);
    draw_text(dl, small, ImVec2(x - text_size(small, t).x * 0.5f, bottom + fs * 0.35f), ink, t);
  }
  for (double v : yt) {
    const float y = sy(v);
    dl->AddLine(ImVec2(left, y), ImVec2(right, y), grid, 1.0f);
    dl->AddLine(ImVec2(left - fs * 0.3f, y), ImVec2(left, y), ink, 1.0f);
    const std::string t = tick_label(v, p.log_y);
    draw_text(dl, small, ImVec2(left - fs * 0.4f - text_size(small, t).x, y - small->FontSize * 0.5f), ink, t);
  }
  dl->AddRect(ImVec2(left, top), ImVec2(right, bottom), ink, 0, 0, 1.0f);
  // Series, clipped to the plot area.
  dl->PushClipRect(ImVec2(left, top), ImVec2(right, bottom), true);
  for (size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    const ImU32 c = kPalette[(s.color >= 0 ? size_t(s.color) : k) % kColours];
    std::vector<ImVec2> pts;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      const double ax = axis_value(s.x[i], p.log_x), ay = axis_value(s.y[i], p.log_y);
      if (std::isfinite(ax) && std::isfinite(ay)) pts.emplace_back(sx(ax), sy(ay));
    }
    if (s.line && pts.size() > 1) {
      if (!s.dashed) {
        dl->AddPolyline(pts.data(), int(pts.size()), c, ImDrawFlags_None, 2.0f);
      } else {
        for (size_t i = 0; i + 1 < pts.size(); i += 2) dl->AddLine(pts[i], pts[i + 1], c, 2.0f);
      }
    }
    if (s.markers)
      for (const ImVec2& q : pts) dl->AddCircleFilled(q, 3.5f, c);
  }
  dl->PopClipRect();
  // Legend, top right inside the plot.
  float lw = 0;
  for (const Series& s : p.series) lw = std::max(lw, text_size(small, s.label).x);
  if (lw > 0) {
    // In the corner of the plot that covers the fewest data points.
    const float row = small->FontSize * 1.3f, box_w = lw + fs * 2.2f, box_h = row * p.series.size() + fs * 0.4f;
    float lx0 = right - fs * 0.4f - box_w, ly0 = top + fs * 0.4f;
    size_t best = ~size_t(0);
    for (int corner = 0; corner < 4; ++corner) {
      const float cx = corner % 2 ? left + fs * 0.4f : right - fs * 0.4f - box_w;
      const float cy = corner / 2 ? bottom - fs * 0.4f - box_h : top + fs * 0.4f;
      size_t covered = 0;
      for (const Series& s : p.series)
        for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
          const double ax = axis_value(s.x[i], p.log_x), ay = axis_value(s.y[i], p.log_y);
          if (!std::isfinite(ax) || !std::isfinite(ay)) continue;
          const float qx = sx(ax), qy = sy(ay);
          covered += qx >= cx && qx <= cx + box_w && qy >= cy && qy <= cy + box_h;
        }
      if (covered < best) {
        best = covered;
        lx0 = cx;
        ly0 = cy;
      }
    }
    const float lx1 = lx0 + box_w;
    dl->AddRectFilled(ImVec2(lx0, ly0), ImVec2(lx1, ly0 + row * p.series.size() + fs * 0.4f), IM_COL32(255, 255, 255, 230));
    dl->AddRect(ImVec2(lx0, ly0), ImVec2(lx1, ly0 + row * p.series.size() + fs * 0.4f), IM_COL32(180, 180, 180, 255));
    for (size_t k = 0; k < p.series.size(); ++k) {
      const Series& s = p.series[k];
      const ImU32 c = kPalette[(s.color >= 0 ? size_t(s.color) : k) % kColours];
      const float y = ly0 + fs * 0.2f + row * k + row * 0.5f;
      if (s.line && !s.dashed) dl->AddLine(ImVec2(lx0 + fs * 0.4f, y), ImVec2(lx0 + fs * 1.8f, y), c, 2.0f);
      if (s.line && s.dashed) {
        dl->AddLine(ImVec2(lx0 + fs * 0.4f, y), ImVec2(lx0 + fs * 0.9f, y), c, 2.0f);
        dl->AddLine(ImVec2(lx0 + fs * 1.3f, y), ImVec2(lx0 + fs * 1.8f, y), c, 2.0f);
      }
      if (s.markers) dl->AddCircleFilled(ImVec2(lx0 + fs * 1.1f, y), 3.5f, c);
      draw_text(dl, small, ImVec2(lx0 + fs * 2.1f, y - small->FontSize * 0.5f), ink, s.label);
    }
  }
}

}  // namespace

bool write_figure_png(const Figure& f, const std::string& path, std::string& error) {
  if (f.panels.empty()) {
    error = path + ": a figure needs at least one panel";
    return false;
  }
  const int cols = std::max(1, std::min(f.columns, int(f.panels.size())));
  const int rows = (int(f.panels.size()) + cols - 1) / cols;
  const int title_h = f.title.empty() ? 0 : 44;
  const int width = cols * f.panel_width, height = title_h + rows * f.panel_height;
  auto canvas = Canvas::create(16.0f, error);
  if (!canvas) return false;
  ImDrawList* dl = canvas->begin(width, height, 0.97f, 0.97f, 0.97f);
  ImGuiLayer& layer = canvas->layer();
  if (!f.title.empty()) {
    ImFont* t = layer.font(FontRole::title);
    draw_text(dl, t, ImVec2((width - text_size(t, f.title).x) * 0.5f, 12.0f), IM_COL32(20, 20, 20, 255), f.title);
  }
  for (size_t i = 0; i < f.panels.size(); ++i) {
    const int c = int(i) % cols, r = int(i) / cols;
    draw_panel(dl, layer, f.panels[i], float(c * f.panel_width), float(title_h + r * f.panel_height), float(f.panel_width),
               float(f.panel_height));
  }
  return write_png(path, canvas->end(), 6, false, error);
}

}  // namespace render
