#pragma once
// Several organs' cost, side by side: assets' gallbladder_retraction scene (a liver and a
// gallbladder tied to it, a grasper retracting the gallbladder, a probe pressing the liver) run
// whole, then with the liver alone and with the gallbladder alone on the same script (the other
// organ and the attachments removed), in turn, round after round: the two-organ run's step
// time over the sum of the single-organ runs'.
namespace vdmsim {

struct OrgansSideBySide {
  long nodes[3] = {0, 0, 0};           // both, liver, gallbladder
  int frames = 0, rounds = 0;
  double total_ms[3] = {0, 0, 0};      // step time over the run, per round (medians of the rounds)
  long iterations[3] = {0, 0, 0};      // core iterations over the run (summed over its organs)
  double ratio = 0;                    // both over liver + gallbladder
  double ratio_min = 0, ratio_max = 0; // round by round
};

OrgansSideBySide bench_organs_side_by_side(int frames, int rounds);

}  // namespace vdmsim
