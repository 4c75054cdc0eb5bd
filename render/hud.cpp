#include "render/hud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/colormap.hpp"
#include "render/view_settings.hpp"

namespace render {

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> out;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return out;
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * mag * 1.0000001) {
      step = m * mag;
      break;
    }
  const double first = std::ceil(lo / step - 1e-9) * step;
  // A range too narrow for the doubles around it (first + step == first) gives no ticks.
  if (!(first + step > first)) return out;
  for (int k = 0; k < 1000; ++k) {
    const double v = first + k * step;
    if (v > hi + step * 1e-9) break;
    out.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  }
  return out;
}

std::pair<double, std::string> display_unit(const std::string& si, double magnitude) {
  magnitude = std::abs(magnitude);
  if (si == "Pa") {
    if (magnitude >= 1e6) return {1e-6, "MPa"};
    if (magnitude >= 1e3) return {1e-3, "kPa"};
    return {1.0, "Pa"};
  }
  if (si == "m") {
    if (magnitude < 1e-3) return {1e6, "um"};
    if (magnitude < 1.0) return {1e3, "mm"};
    return {1.0, "m"};
  }
  if (si == "N") {
    if (magnitude < 1.0 && magnitude > 0) return {1e3, "mN"};
    return {1.0, "N"};
  }
  return {1.0, si};
}

std::string format_number(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  std::string s = buf;
  return s == "-0" ? "0" : s;
}

namespace {

void draw_colour_bar(ImDrawList* dl, const ImGuiLayer& layer, const StressView& view, int width, int height) {
  ImFont* body = layer.font(FontRole::body);
  ImFont* small = layer.font(FontRole::small);
  const float fs = body->FontSize;
  const float bar_w = std::max(10.0f, fs * 0.9f), bar_h = height * 0.55f;
  const float x1 = width - fs * 4.6f, x0 = x1 - bar_w;
  const float y0 = (height - bar_h) * 0.5f + fs, y1 = y0 + bar_h;
  const std::string si = quantity_unit(view.quantity);
  const auto [scale, unit] = display_unit(si, std::max(std::abs(view.lo), std::abs(view.hi)));
  std::string title = quantity_label(view.quantity);
  if (!unit.empty()) title += " (" + unit + ")";
  // Backing panel.
  const ImVec2 tsize = text_size(body, title);
  const float panel_x0 = std::min(x0 - fs * 0.6f, width - tsize.x - fs * 1.2f);
  dl->AddRectFilled(ImVec2(panel_x0, y0 - fs * 2.4f), ImVec2(width - fs * 0.4f, y1 + fs * 1.0f), IM_COL32(20, 22, 26, 170),
                    fs * 0.4f);
  draw_text(dl, body, ImVec2(width - fs * 0.8f - tsize.x, y0 - fs * 1.9f), IM_COL32(240, 240, 240, 255), title);
  // The bar: one band per table step, high values on top.
  const auto& table = colormap_table(view.colormap);
  const int bands = 128;
  for (int i = 0; i < bands; ++i) {
    const Rgb8 c = table[static_cast<size_t>((i * 255) / (bands - 1))];
    const float yb = y1 - bar_h * i / bands, yt = y1 - bar_h * (i + 1) / bands;
    dl->AddRectFilled(ImVec2(x0, yt - 0.5f), ImVec2(x1, yb + 0.5f), IM_COL32(c.r, c.g, c.b, 255));
  }
  dl->AddRect(ImVec2(x0 - 0.5f, y0 - 0.5f), ImVec2(x1 + 0.5f, y1 + 0.5f), IM_COL32(235, 235, 235, 255), 0, 0, 1.0f);
  // Ticks and labels in display units.
  const double lo = view.lo * scale, hi = view.hi * scale;
  for (double v : nice_ticks(lo, hi, 5)) {
    const float y = float(y1 - (v - lo) / (hi - lo) * bar_h);
    dl->AddLine(ImVec2(x1, y), ImVec2(x1 + fs * 0.35f, y), IM_COL32(235, 235, 235, 255), 1.0f);
    const std::string label = format_number(v, 4);
    draw_text(dl, small, ImVec2(x1 + fs * 0.5f, y - small->FontSize * 0.5f), IM_COL32(235, 235, 235, 255), label);
  }
}

}  // namespace

void draw_hud(ImDrawList* dl, const ImGuiLayer& layer, const HudInfo& hud, int width, int height, const StressView* stress) {
  ImFont* title = layer.font(FontRole::title);
  ImFont* body = layer.font(FontRole::body);
  const float fs = body->FontSize;
  const std::vector<std::string> lines = hud_lines(hud);
  float text_w = text_size(title, hud.scene_name).x;
  for (const std::string& l : lines) text_w = std::max(text_w, text_size(body, l).x);
  const float pad = fs * 0.6f, line_h = fs * 1.3f;
  const float panel_h = pad * 2 + title->FontSize * 1.35f + line_h * lines.size();
  dl->AddRectFilled(ImVec2(pad, pad), ImVec2(pad * 3 + text_w, pad + panel_h), IM_COL32(20, 22, 26, 170), fs * 0.4f);
  float y = pad * 2;
  draw_text(dl, title, ImVec2(pad * 2, y), IM_COL32(255, 255, 255, 255), hud.scene_name);
  y += title->FontSize * 1.35f;
  for (const std::string& l : lines) {
    draw_text(dl, body, ImVec2(pad * 2, y), IM_COL32(230, 232, 235, 255), l);
    y += line_h;
  }
  (void)height;
  if (stress) draw_colour_bar(dl, layer, *stress, width, height);
}

}  // namespace render
