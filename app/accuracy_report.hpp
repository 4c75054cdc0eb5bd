#pragma once
// What `vdmsim accuracy` writes: accuracy.csv (one row per configuration), accuracy.png
// (error against time, log-log, the Pareto front marked) and recommendations.md (settings for
// haptic rate, video rate and offline accuracy, read off the rows).
#include <string>
#include <vector>

#include "app/accuracy.hpp"

namespace vdmsim {

bool write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error);
bool write_accuracy_plot(const std::string& path, const std::vector<AccuracyRow>& rows, std::string& error);

// What a use judges accuracy by: the instrument force (a haptic device renders forces) or
// the surface displacement (what a picture shows).
enum class AccuracyMetric { force, displacement };

// The use cases, their time budgets per step (ms) and what they judge accuracy by.
struct UseBudget {
  const char* name;
  double budget_ms;
  const char* why;
  AccuracyMetric metric;
};
const std::vector<UseBudget>& use_budgets();

// The most accurate row of `scenario` by `metric` (smallest force error, or smallest RMS
// displacement error; ties to the faster) within `budget_ms` per step, the reference
// excluded; null when none fits.
const AccuracyRow* best_within(const std::vector<AccuracyRow>& rows, const std::string& scenario, double budget_ms,
                               AccuracyMetric metric = AccuracyMetric::displacement);

bool write_recommendations(const std::string& path, const std::vector<AccuracyRow>& rows, bool quick,
                           std::string& error);

}  // namespace vdmsim
