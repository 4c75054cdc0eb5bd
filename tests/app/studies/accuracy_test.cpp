// The accuracy study's pieces: the configuration sweep, the Pareto front and the choice of
// recommended settings.
#include <gtest/gtest.h>

#include <set>

#include "app/studies/accuracy.hpp"
#include "app/studies/accuracy_report.hpp"
#include "app/studies/ladder.hpp"
#include "app/studies/ladder_cases.hpp"
#include "app/studies/ladder_errors.hpp"

namespace vdmsim {
namespace {

AccuracyRow row(const char* scenario, const char* varied, double ms, double rms) {
  AccuracyRow r;
  r.config.scenario = scenario;
  r.config.varied = varied;
  r.median_ms = ms;
  r.rms_mm = rms;
  return r;
}

TEST(Accuracy, EveryScenarioHasAReferenceFirstAndEveryKnobVaried) {
  for (bool quick : {true, false}) {
    const std::vector<AccuracyConfig> configs = accuracy_configs(quick);
    for (const char* scenario : {"probe_poke", "grasp_lift"}) {
      std::set<std::string> varied;
      const AccuracyConfig* ref = nullptr;
      int finest = 0;
      for (const AccuracyConfig& c : configs) {
        if (c.scenario != scenario) continue;
        if (!ref) ref = &c;
        varied.insert(c.varied);
        finest = std::max(finest, c.level);
      }
      ASSERT_NE(ref, nullptr);
      EXPECT_EQ(ref->varied, "reference");
      // The reference is the converged end of every knob.
      EXPECT_EQ(ref->level, finest);
      EXPECT_EQ(ref->refresh_every, 1);
      EXPECT_GT(ref->nonlinear_iterations, 1);
      for (const AccuracyConfig& c : configs)
        if (c.scenario == scenario && c.model == vdm::ModelKind::vdm) {
          EXPECT_LE(ref->tolerance, c.tolerance);
        }
      for (const char* knob : {"baseline", "solver", "tolerance", "refresh", "nonlinear", "mesh", "capsule", "model"})
        EXPECT_TRUE(varied.count(knob)) << scenario << " " << knob << (quick ? " quick" : "");
    }
  }
}

TEST(Accuracy, ScenarioAndKnobsNarrowTheStudyKeepingItsReferenceAndBaseline) {
  const std::vector<AccuracyConfig> all = accuracy_configs(true);
  AccuracyOptions o;
  o.quick = true;
  std::vector<int> which;
  std::string error;
  ASSERT_TRUE(select_accuracy_configs(o, which, error)) << error;
  EXPECT_EQ(which.size(), all.size());
  o.scenario = "grasp_lift";
  o.only = "tolerance,mesh";
  ASSERT_TRUE(select_accuracy_configs(o, which, error)) << error;
  std::vector<std::string> varied;
  for (int i : which) {
    EXPECT_EQ(all[size_t(i)].scenario, "grasp_lift");
    varied.push_back(all[size_t(i)].varied);
  }
  // The indices are the whole study's, in its order: the reference first.
  EXPECT_EQ(varied, (std::vector<std::string>{"reference", "baseline", "tolerance", "tolerance", "mesh"}));
  EXPECT_GT(which.front(), 0);
  o.only = "tolerance,meshes";
  EXPECT_FALSE(select_accuracy_configs(o, which, error));
  EXPECT_NE(error.find("--only: unknown knob 'meshes'; known knobs: solver, tolerance"), std::string::npos) << error;
  o.only.clear();
  o.scenario = "liver";
  EXPECT_FALSE(select_accuracy_configs(o, which, error));
  EXPECT_NE(error.find("--scenario: unknown scenario 'liver'; known scenarios: probe_poke, grasp_lift"), std::string::npos)
      << error;
}

TEST(Accuracy, ParetoFrontKeepsOnlyUndominatedRowsPerScenario) {
  std::vector<AccuracyRow> rows = {
      row("probe_poke", "reference", 100, 0),    // never on the front
      row("probe_poke", "baseline", 10, 0.1),    // front
      row("probe_poke", "tolerance", 2, 0.5),    // front
      row("probe_poke", "tolerance", 12, 0.2),   // dominated by baseline
      row("probe_poke", "mesh", 2, 0.6),         // dominated (same time, larger error)
      row("grasp_lift", "baseline", 50, 1.0),    // another scenario: front of its own
  };
  rows.push_back(row("probe_poke", "model", 1, 0.05));
  rows.back().failed = true;                     // failed rows take no part
  mark_pareto(rows);
  const std::vector<bool> expected = {false, true, true, false, false, true, false};
  for (size_t k = 0; k < rows.size(); ++k) EXPECT_EQ(rows[k].pareto, expected[k]) << k;
}

TEST(Accuracy, RecommendationIsTheFastestNearlyMostAccurateWithinTheBudget) {
  std::vector<AccuracyRow> rows = {
      row("probe_poke", "reference", 0.1, 0),   // excluded even though fastest and exact
      row("probe_poke", "mesh", 0.6, 0.3),
      row("probe_poke", "tolerance", 0.9, 0.4),
      row("probe_poke", "baseline", 8, 0.100),
      row("probe_poke", "refresh", 5, 0.104),   // within 5 % of the baseline's error, faster
      row("probe_poke", "solver", 20, 0.090),   // clearly more accurate, slower
  };
  for (AccuracyRow& r : rows) r.p95_ms = 2 * r.median_ms;
  rows[1].force_rel = 1.4;   // the coarse mesh: displacements fine, force far off
  rows[2].force_rel = 0.05;
  rows[3].force_rel = 0.04;
  rows[4].force_rel = 0.04;
  rows[5].force_rel = 0.04;
  EXPECT_EQ(best_within(rows, "probe_poke", 1.0)->config.varied, "mesh");
  EXPECT_EQ(best_within(rows, "probe_poke", 1.0, AccuracyMetric::force)->config.varied, "tolerance");
  // Held to the 95th percentile, nothing fits 1 ms (p95 1.2 and 1.8 ms).
  EXPECT_EQ(best_within(rows, "probe_poke", 1.0, AccuracyMetric::force, true), nullptr);
  EXPECT_EQ(best_within(rows, "probe_poke", 12)->config.varied, "refresh");
  EXPECT_EQ(best_within(rows, "probe_poke", 1e9)->config.varied, "solver");
  EXPECT_EQ(best_within(rows, "probe_poke", 33, AccuracyMetric::force)->config.varied, "refresh");
  EXPECT_EQ(best_within(rows, "probe_poke", 0.2), nullptr);
  EXPECT_EQ(best_within(rows, "grasp_lift", 1e9), nullptr);
  // Every use has a budget and says what it judges by; real-time ones hold the p95.
  ASSERT_EQ(use_budgets().size(), 3u);
  EXPECT_EQ(use_budgets()[0].metric, AccuracyMetric::force);
  EXPECT_LE(use_budgets()[0].budget_ms, 1.0);
  EXPECT_TRUE(use_budgets()[0].worst_case);
  EXPECT_LE(use_budgets()[1].budget_ms, 1000.0 / 30);
  EXPECT_TRUE(use_budgets()[1].worst_case);
}

TEST(AccuracyLadder, EveryCaseHasItsReferenceFemFirstAndEveryModel) {
  for (const bool quick : {true, false}) {
    const std::vector<LadderConfig> all = ladder_configs(quick);
    std::set<std::string> names, cases;
    std::string last_case;
    for (const LadderConfig& c : all) {
      EXPECT_TRUE(names.insert(ladder_config_name(c)).second) << ladder_config_name(c);
      if (c.test_case != last_case) {
        // A new case starts with its reference, the FEM, and never comes back.
        EXPECT_TRUE(c.reference && c.model == LadderModel::fem) << ladder_config_name(c);
        EXPECT_TRUE(cases.insert(c.test_case).second) << c.test_case;
        last_case = c.test_case;
      } else {
        EXPECT_FALSE(c.reference) << ladder_config_name(c);
      }
    }
    EXPECT_EQ(cases, (std::set<std::string>{"punch", "stretch", "bend", "twist", "liver_probe"}));
    for (const std::string& which : cases)
      for (const LadderModel m : {LadderModel::vdm_paper, LadderModel::vdm_membrane, LadderModel::vdm_core}) {
        int n = 0;
        for (const LadderConfig& c : all) n += c.test_case == which && c.model == m;
        EXPECT_GE(n, 1) << which << ' ' << to_string(m);
        if (m == LadderModel::vdm_core) {
          EXPECT_GE(n, 2) << which << ": the core at several cell sizes";
        }
      }
  }
  std::vector<int> picked;
  std::string error;
  ASSERT_TRUE(select_ladder_configs(true, "beams", picked, error));
  for (const int i : picked) EXPECT_EQ(ladder_configs(true)[size_t(i)].scenario, "beams");
  EXPECT_FALSE(select_ladder_configs(true, "probe_poke", picked, error));
  EXPECT_NE(error.find("punch, beams, liver_probe"), std::string::npos) << error;
}

// A trajectory of `frames` frames whose every point is `u` (and the force F along z).
Trajectory ladder_trajectory(int points, const vdm::Vec3& u, double force, int frames = 2) {
  Trajectory tr;
  for (int f = 0; f < frames; ++f) {
    vdm::NodeMat at(points, 3);
    at.rowwise() = u.transpose();
    tr.u.push_back(at);
    tr.force.push_back(vdm::Vec3(0, 0, force));
    tr.step_ms.push_back(1.0 + f);
    tr.volume_rel.push_back(f ? -2e-12 : 1e-12);
  }
  tr.nodes = 42;
  return tr;
}

TEST(AccuracyLadder, MeasuresAreRelativeToTheReference) {
  LadderRow beam;
  beam.config.scenario = "beams";
  beam.config.test_case = "bend";
  measure_ladder_row(ladder_trajectory(3, vdm::Vec3(0.003, 0, 0.004), 0),
                     ladder_trajectory(3, vdm::Vec3(0, 0.0045, 0), 0), beam);
  EXPECT_NEAR(beam.error, 0.1, 1e-12);  // |u| 4.5 mm against 5 mm
  EXPECT_EQ(beam.force_error, -1);
  EXPECT_NEAR(beam.volume_rel_error, 2e-12, 1e-24);
  EXPECT_EQ(beam.nodes, 42);
  EXPECT_NEAR(beam.measured_median_ms, 1.5, 1e-12);

  LadderRow punch;
  punch.config.scenario = "punch";
  punch.config.test_case = "punch";
  const int points = kLadderPunchRadii * kLadderPunchAzimuths;
  measure_ladder_row(ladder_trajectory(points, vdm::Vec3(0, 0, -0.0004), 0.04),
                     ladder_trajectory(points, vdm::Vec3(0, 0, -0.0005), 0.03), punch);
  EXPECT_NEAR(punch.error, 0.25, 1e-12);
  EXPECT_NEAR(punch.force_error, 0.25, 1e-12);
  EXPECT_NE(punch.detail.find("+25.0"), std::string::npos) << punch.detail;
}

}  // namespace
}  // namespace vdmsim
