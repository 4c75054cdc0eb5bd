#pragma once
// What `vdmsim accuracy` writes: accuracy.csv (one row per configuration), accuracy.png
// (error against time, log-log, the Pareto front marked) and recommendations.md (settings for
// haptic rate, video rate and offline accuracy, read off the rows).
#include <string>
#include <vector>

#include "app/studies/accuracy.hpp"

namespace vdmsim {

bool write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error);
bool write_accuracy_plot(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error);

// What a use judges accuracy by: the instrument force (a haptic device renders forces) or
// the surface displacement (what a picture shows).
enum class AccuracyMetric { force, displacement };

// The use cases, their time budgets per step (ms) and what they judge accuracy by.
// Real-time uses hold the 95th percentile of the step time to the budget, not the median.
struct UseBudget {
  const char* name;
  double budget_ms;
  const char* why;
  AccuracyMetric metric;
  bool worst_case;  // budget applies to p95_ms (else median_ms)
};
const std::vector<UseBudget>& use_budgets();

// Among the rows of `scenario` within `budget_ms` per step (p95 when `worst_case`, else the
// median; the reference excluded), the fastest (median) of those whose error by `metric`
// (force error or RMS displacement error) is within 5 % of the smallest: differences below
// that are not worth paying time for. Null when none fits.
const AccuracyRow* best_within(const std::vector<AccuracyRow>& rows, const std::string& scenario, double budget_ms,
                               AccuracyMetric metric = AccuracyMetric::displacement, bool worst_case = false);

bool write_recommendations(const std::string& path, const std::vector<AccuracyRow>& rows, bool quick,
                           std::string& error);

}  // namespace vdmsim
