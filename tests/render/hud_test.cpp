// The HUD's lines: the fluid pressure named as such, and values within round-off of zero
// shown as 0 while real values, however small against the scale, keep their digits.
#include <gtest/gtest.h>

#include <string>

#include "render/hud_text.hpp"
#include "render/number_format.hpp"

namespace render {
namespace {

HudInfo info() {
  HudInfo h;
  h.frame = 0;
  h.frames = 30;
  h.time_s = 0.0333333;
  h.has_contact = true;
  h.pressure_scale_pa = 20000;         // the moduli
  h.force_scale_n = 20000 * 0.3 * 0.3;  // times the organ's size squared
  return h;
}

TEST(Hud, RoundOffReadsZero) {
  HudInfo h = info();
  h.pressure_pa = -3e-17;
  h.contact_force_n = 2e-15;
  h.volume_rel_error = -4e-17;
  const std::vector<std::string> lines = hud_lines(h);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[1], "contact force  0 N");
  EXPECT_EQ(lines[2], "fluid pressure  0 Pa");
  EXPECT_EQ(lines[3], "volume error  0");
}

TEST(Hud, SmallButRealValuesKeepTheirDigits) {
  HudInfo h = info();
  h.pressure_pa = -0.25;               // 1e-5 of the moduli: a real pressure
  h.contact_force_n = 0.0042;
  h.volume_rel_error = 3.4e-9;
  const std::vector<std::string> lines = hud_lines(h);
  EXPECT_EQ(lines[0], "frame 0 / 29    t = 0.033 s");
  EXPECT_EQ(lines[1], "contact force  4.2 mN");
  EXPECT_EQ(lines[2], "fluid pressure  -0.25 Pa");
  EXPECT_EQ(lines[3], "volume error  3.40e-09");
  h.has_contact = false;
  EXPECT_EQ(hud_lines(h)[1], "contact  not simulated");
}

TEST(Hud, ZeroIfRoundoffIsRelativeToTheScale) {
  EXPECT_EQ(zero_if_roundoff(1e-7, 1e4), 1e-7);   // 1e-11 of the scale: kept
  EXPECT_EQ(zero_if_roundoff(-1e-9, 1e4), 0.0);   // 1e-13 of the scale: round-off
  EXPECT_EQ(zero_if_roundoff(0.5, 0), 0.5);       // no scale: only exact zeros are zero
}

}  // namespace
}  // namespace render
