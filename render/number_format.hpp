#pragma once
// Axis ticks, display units and compact numbers for the HUD's colour bar and for plots.
#include <string>
#include <utility>
#include <vector>

namespace render {

// "Nice" tick values (1, 2, 5 x 10^k) covering [lo, hi], about `target` of them.
std::vector<double> nice_ticks(double lo, double hi, int target);
// A display unit for values up to `magnitude` of an SI unit: {scale, label}; e.g. Pa with
// 4000 -> {1e-3, "kPa"}, m with 0.02 -> {1e3, "mm"}.
std::pair<double, std::string> display_unit(const std::string& si_unit, double magnitude);
// A compact number: up to `digits` significant digits, no trailing zeros.
std::string format_number(double v, int digits = 3);
// `v`, or 0 when it is within round-off of zero for a quantity whose values are of the order of
// `scale` (|v| < 1e-12 scale): a pressure of 3e-17 Pa where the moduli are 20 kPa is a zero.
double zero_if_roundoff(double v, double scale);

}  // namespace render
