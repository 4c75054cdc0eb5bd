#include "render/hud_text.hpp"

#include <cmath>
#include <cstdio>

#include "render/number_format.hpp"

namespace render {

double zero_if_roundoff(double v, double scale) { return std::abs(v) < 1e-12 * std::abs(scale) ? 0.0 : v; }

namespace {

std::string with_unit(double v, const std::string& si, int digits = 3) {
  const auto [scale, unit] = display_unit(si, v);
  return format_number(v * scale, digits) + " " + unit;
}

}  // namespace

std::vector<std::string> hud_lines(const HudInfo& hud) {
  std::vector<std::string> lines;
  char buf[160];
  std::snprintf(buf, sizeof buf, "frame %d / %d    t = %.3f s", hud.frame, hud.frames - 1, hud.time_s);
  lines.push_back(buf);
  lines.push_back(hud.has_contact ? "contact force  " + with_unit(zero_if_roundoff(hud.contact_force_n, hud.force_scale_n), "N")
                                   : "contact  not simulated");
  lines.push_back("fluid pressure  " + with_unit(zero_if_roundoff(hud.pressure_pa, hud.pressure_scale_pa), "Pa"));
  const double volume_error = zero_if_roundoff(hud.volume_rel_error, 1.0);
  if (volume_error == 0) std::snprintf(buf, sizeof buf, "volume error  0");
  else std::snprintf(buf, sizeof buf, "volume error  %.2e", volume_error);
  lines.push_back(buf);
  if (hud.show_step_time) {
    std::snprintf(buf, sizeof buf, "step  %.2f ms", hud.step_ms);
    lines.push_back(buf);
  }
  return lines;
}

}  // namespace render
