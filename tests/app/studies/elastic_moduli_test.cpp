// The E, nu rule for VDM's moduli (engine/elastic_moduli.hpp, docs/model.md) on shapes that
// were not in its fit: against the FEM on the organ's default load cases (a top patch pressed
// and pulled sideways, the base held), it does nearly as well as the best moduli fitted to
// that very organ.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "app/scene/organ_generator.hpp"
#include "app/simulation/tet_mesher.hpp"
#include "app/studies/calibrate.hpp"
#include "engine/shapes.hpp"

namespace vdmsim {
namespace {

void expect_rule_near_the_fit(const std::string& what, const vdm::SurfaceMesh& surface, double young, double poisson) {
  vdm::fem::TetMesh tets;
  std::string error;
  ASSERT_TRUE(tetrahedralize(surface, 0, tets, error)) << error;
  OrganCalibration c;
  ASSERT_TRUE(calibrate_organ(surface, tets, young, poisson, 4, c));
  const CalibrationResult &fit = c.fit, &by_rule = c.rule;
  std::printf("%s (E %g Pa, nu %g): fit B %.4g B_ij %.4g: RMS u %.2f %%, work %.2f %%; rule B %.4g B_ij %.4g: RMS u %.2f %%, "
              "work %.2f %%\n",
              what.c_str(), young, poisson, fit.params.bulk, fit.params.connectivity, 100 * fit.rms_displacement,
              100 * fit.rms_work, by_rule.params.bulk, by_rule.params.connectivity, 100 * by_rule.rms_displacement, 100 * by_rule.rms_work);
  EXPECT_LE(by_rule.rms_displacement, 1.4 * fit.rms_displacement) << what;
  EXPECT_LE(by_rule.rms_work, fit.rms_work + 0.05) << what;
}

TEST(ElasticModuliRule, HeldOutBeamAndLiverAgainstTheFem) {
  // A 2 x 10 x 2 cm beam standing on its end, and the project's liver at level 3 (642 nodes),
  // at a Poisson's ratio inside the fit's range and at one below it.
  expect_rule_near_the_fit("beam", vdm::make_box(vdm::Vec3(0.02, 0.1, 0.02), 3, 15, 3), 3000, 0.45);
  expect_rule_near_the_fit("liver", make_liver_mesh(3), 3000, 0.45);
  expect_rule_near_the_fit("liver", make_liver_mesh(3), 5000, 0.3);
}

}  // namespace
}  // namespace vdmsim
