#pragma once
// Several organs' cost, side by side: assets' gallbladder_retraction scene (a liver and a
// gallbladder tied to it, a grasper retracting the gallbladder, a probe pressing the liver) run
// whole, then with the liver alone and with the gallbladder alone on the same script (the other
// organ and the attachments removed), in turn, round after round: the two-organ run's step
// time over the sum of the single-organ runs'. Alone, an organ misses the other's pull (the
// liver, never reached by the grasper, stands still), so each organ is also run alone under
// the forces the other put on it in the two-organ run (its ties' and contact's, per node, frame
// by frame, as external loads): the same deformation, solved without the coupling. The second
// ratio, over those, is what stepping the organs together costs.
namespace vdmsim {

struct OrgansSideBySide {
  // 0 both, 1 the liver alone, 2 the gallbladder alone, 3 the liver alone under the
  // gallbladder's forces, 4 the gallbladder alone under the liver's
  static constexpr int kRuns = 5;
  long nodes[3] = {0, 0, 0};           // both, liver, gallbladder
  int frames = 0, rounds = 0;
  double total_ms[kRuns] = {};         // step time over the run, per round (medians of the rounds)
  long iterations[kRuns] = {};         // core iterations over the run (summed over its organs)
  double ratio = 0;                    // both over liver + gallbladder
  double ratio_min = 0, ratio_max = 0; // round by round
  double replayed_ratio = 0;           // both over liver + gallbladder, each under the other's forces
  double replayed_ratio_min = 0, replayed_ratio_max = 0;
};

OrgansSideBySide bench_organs_side_by_side(int frames, int rounds);

}  // namespace vdmsim
