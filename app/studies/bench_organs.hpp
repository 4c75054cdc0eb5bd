#pragma once
// Several organs' cost, side by side: assets' gallbladder_retraction scene (a liver and a
// gallbladder tied to it, a grasper retracting the gallbladder, a probe pressing the liver) run
// whole, then with the liver alone and with the gallbladder alone on the same script (the other
// organ and the attachments removed), in turn, round after round: the two-organ run's step
// time over the sum of the single-organ runs'. Alone, an organ misses the other's pull (the
// liver, never reached by the grasper, stands still), so each organ is also run alone with the
// other following the surface it had in the two-organ run (sub-step by sub-step, a surface
// that does not yield, met through the ties and contact): the same deformation, solved without
// the other's answer. The second ratio, over those, is what stepping the organs together costs.
// Against a surface that does not yield an organ takes more iterations than beside the organ
// itself, so a third ratio counts each organ alone (the other following) at the iterations it
// took in the two-organ run: the cost of an iteration together over alone.
namespace vdmsim {

struct OrgansSideBySide {
  // 0 both, 1 the liver alone, 2 the gallbladder alone, 3 the liver alone with the
  // gallbladder following its recorded surface, 4 the gallbladder alone with the liver following
  static constexpr int kRuns = 5;
  long nodes[3] = {0, 0, 0};           // both, liver, gallbladder
  int frames = 0, rounds = 0;
  double total_ms[kRuns] = {};         // step time over the run, per round (medians of the rounds)
  long iterations[kRuns] = {};         // core iterations over the run (summed over its organs)
  long unconverged[kRuns] = {};        // contact steps (sub-steps, per organ) ended unconverged
  double ratio = 0;                    // both over liver + gallbladder
  double ratio_min = 0, ratio_max = 0; // round by round
  double replayed_ratio = 0;           // both over liver + gallbladder, each with the other following
  double replayed_ratio_min = 0, replayed_ratio_max = 0;
  // The two-organ run's core iterations per organ (liver, gallbladder), and its step time over
  // the organs alone (the other following) counted at those iterations, each at its cost per
  // iteration there: what an iteration of the organs together costs over one of each alone.
  long iterations_together[2] = {0, 0};
  // How far each replayed organ's last surface is from the two-organ run's (m): liver, gallbladder.
  double replayed_apart_m[2] = {0, 0};
  double per_iteration_ratio = 0;
  double per_iteration_ratio_min = 0, per_iteration_ratio_max = 0;
};

OrgansSideBySide bench_organs_side_by_side(int frames, int rounds);

}  // namespace vdmsim
