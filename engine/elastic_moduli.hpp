#pragma once
// VDM's moduli for a tissue given as Young's modulus E and Poisson's ratio ν (docs/model.md,
// "material from E and ν"): B = β E, B_ij = γ(ν) E, the membrane capsule's rule. β and γ were
// fitted once, with `vdmsim calibrate` against the project's FEM (C3D4, gmsh), on two shapes (a
// 10 x 10 x 5 cm block and a 6 cm cube, ν = 0.3, 0.45, 0.49), and are checked on shapes not in
// the fit (the liver; tests/app/studies/elastic_moduli_test.cpp).
namespace vdm {

struct VdmModuli {
  double bulk = 0;          // B (Pa)
  double connectivity = 0;  // B_ij (Pa)
};

constexpr double kBulkPerYoung = 0.0892;          // β: geometric mean of the fitted B/E
constexpr double kConnectivityPerYoung = 0.2535;  // γ at ν = 0.45: geometric mean of the fitted B_ij/E
constexpr double kConnectivityPoissonSlope = 0.62;  // relative change of γ per unit ν (the fits' trend)

inline VdmModuli vdm_moduli_from_elastic(double young, double poisson) {
  return {kBulkPerYoung * young, kConnectivityPerYoung * (1.0 + kConnectivityPoissonSlope * (poisson - 0.45)) * young};
}

}  // namespace vdm
