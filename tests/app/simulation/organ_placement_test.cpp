// organ.rotate_deg and organ.translate: the organ turned about its scaled bounding box's
// centre (x, then y, then z, fixed axes), then moved; regions select on the placed organ.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "app/scene/mesh_io.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "support/scratch_dir.hpp"

namespace vdmsim {
namespace {

PreparedScene prepare(const std::string& organ_extra, const std::string& name) {
  const std::filesystem::path p = test::scratch_dir("organ_placement") / (name + ".yaml");
  std::ofstream(p) << "organ:\n  mesh: " << VDMSIM_SOURCE_DIR << "/assets/meshes/liver_L4.obj\n  scale: 1000\n"
                   << organ_extra << "simulation: {frames: 1, dt: 0.01}\n";
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_TRUE(prepare_scene(p.string(), ps, problems)) << (problems.empty() ? "" : problems[0].text());
  return ps;
}

TEST(OrganPlacement, RotateAboutTheBoxCentreThenTranslate) {
  const PreparedScene plain = prepare("", "plain");
  const PreparedScene placed = prepare("  rotate_deg: [90, 0, 90]\n  translate: [1, 2, 3]\n", "placed");
  const vdm::NodeMat& a = plain.organ().model.rest.positions;
  const vdm::NodeMat& b = placed.organ().model.rest.positions;
  ASSERT_EQ(a.rows(), b.rows());
  const vdm::Vec3 c = 0.5 * (a.colwise().minCoeff() + a.colwise().maxCoeff()).transpose();
  // x by 90 deg: (x, y, z) -> (x, -z, y); then z by 90 deg: (x, y, z) -> (-y, x, z).
  for (Eigen::Index i = 0; i < a.rows(); i += 97) {
    const vdm::Vec3 d = a.row(i).transpose() - c;
    const vdm::Vec3 want = c + vdm::Vec3(d.z(), d.x(), d.y()) + vdm::Vec3(1, 2, 3);
    EXPECT_LT((b.row(i).transpose() - want).norm(), 1e-9 * 1000) << "node " << i;
  }
  // The volume and the extents are the placed organ's (290 mm long along x becomes along y).
  const vdm::Vec3 sa = a.colwise().maxCoeff() - a.colwise().minCoeff(), sb = b.colwise().maxCoeff() - b.colwise().minCoeff();
  EXPECT_NEAR(sb.y(), sa.x(), 1e-6);
  EXPECT_NEAR(sb.z(), sa.y(), 1e-6);
}

TEST(OrganPlacement, RegionsSelectOnThePlacedOrgan) {
  // A box around the moved organ's bottom holds nodes; around the unmoved one's it selects none.
  const PreparedScene moved = prepare("  translate: [0, 0, 1000]\n  fixed: [{box: {min: [-1000, -1000, 900], max: [1000, 1000, 970]}}]\n",
                                      "moved");
  EXPECT_GT(moved.organ().model.n, 0);
  const std::filesystem::path p = test::scratch_dir("organ_placement") / "miss.yaml";
  std::ofstream(p) << "organ:\n  mesh: " << VDMSIM_SOURCE_DIR << "/assets/meshes/liver_L4.obj\n  scale: 1000\n"
                   << "  translate: [0, 0, 1000]\n  fixed: [{box: {min: [-1000, -1000, -100], max: [1000, 1000, -30]}}]\n"
                   << "simulation: {frames: 1, dt: 0.01}\n";
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  EXPECT_FALSE(prepare_scene(p.string(), ps, problems));
  ASSERT_FALSE(problems.empty());
  EXPECT_NE(problems[0].text().find("after scale, rotate_deg and translate"), std::string::npos) << problems[0].text();
}

}  // namespace
}  // namespace vdmsim
