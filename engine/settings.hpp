#pragma once
// Definition structs with defaults (Box2D style): what a user sets to build a TissueModel.
#include <string>

namespace vdm {

enum class SolverMethod {
  reference,   // the paper's: assembled 3N+1 system, BiCGSTAB warm-started
  structured,  // per-axis SPD solves (PCG, IC(0)) plus the rank-one pressure coupling
  direct,      // per-axis sparse LDL^T, factorisation reused while the matrix is unchanged
};

const char* to_string(SolverMethod m);
bool parse_solver_method(const std::string& text, SolverMethod& out);

struct SolverSettings {
  SolverMethod method = SolverMethod::structured;
  double tolerance = 1e-8;       // relative residual of each linear solve (structured: the three axes together)
  int max_iterations = 2000;     // per Krylov solve
  bool warm_start = true;        // start each Krylov solve from the previous step's solution
  int refresh_every = 1;         // recompute geometry and matrix every k steps (>= 1)
  int nonlinear_iterations = 1;  // max solves per step (1 = the paper's one update per step)
  double nonlinear_tolerance = 1e-10;  // stop iterating when max |du| < this x model size
  // After each solve, Newton corrections of the pressure alone (u += dP' s, with K s = a)
  // bring the exact volume back to V_0: the linear system stays satisfied, the volume
  // error drops quadratically. 0 corrections = the paper's single linearised row.
  int volume_corrections = 6;
  double volume_tolerance = 1e-11;     // relative volume error that needs no correction
};

}  // namespace vdm
