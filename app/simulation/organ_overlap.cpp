#include "app/simulation/organ_overlap.hpp"

#include <fcl/fcl.h>

#include <memory>
#include <vector>

#include "app/simulation/tool_depth.hpp"

namespace vdmsim {
namespace {

using Model = fcl::BVHModel<fcl::OBBRSSd>;

std::shared_ptr<Model> mesh_model(const vdm::NodeMat& x, const vdm::TriMat& t) {
  std::vector<fcl::Vector3d> points(static_cast<size_t>(x.rows()));
  for (Eigen::Index i = 0; i < x.rows(); ++i) points[static_cast<size_t>(i)] = x.row(i).transpose();
  std::vector<fcl::Triangle> triangles(static_cast<size_t>(t.rows()));
  for (Eigen::Index f = 0; f < t.rows(); ++f) triangles[static_cast<size_t>(f)] = fcl::Triangle(t(f, 0), t(f, 1), t(f, 2));
  auto model = std::make_shared<Model>();
  model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
  model->addSubModel(points, triangles);
  model->endModel();
  return model;
}

bool boxes_overlap(const vdm::NodeMat& a, const vdm::NodeMat& b) {
  const vdm::Vec3 alo = a.colwise().minCoeff(), ahi = a.colwise().maxCoeff();
  const vdm::Vec3 blo = b.colwise().minCoeff(), bhi = b.colwise().maxCoeff();
  return (alo.array() <= bhi.array()).all() && (blo.array() <= ahi.array()).all();
}

}  // namespace

OrganOverlap find_overlap(const vdm::NodeMat& xa, const vdm::TriMat& ta, const vdm::NodeMat& xb,
                          const vdm::TriMat& tb, int pairs) {
  OrganOverlap out;
  if (xa.rows() == 0 || xb.rows() == 0 || !boxes_overlap(xa, xb)) return out;
  const fcl::CollisionObjectd a(mesh_model(xa, ta)), b(mesh_model(xb, tb));
  fcl::CollisionRequestd request(static_cast<size_t>(pairs), false);
  fcl::CollisionResultd result;
  fcl::collide(&a, &b, request, result);
  if (!result.isCollision()) return out;
  out.crossing = true;
  std::vector<fcl::Contactd> contacts;
  result.getContacts(contacts);
  // Each side's nodes inside the other: from the crossing triangles' corners, through the
  // surface's edges, as long as the nodes are inside (the part of the surface within the
  // other organ, up to kMostVisited nodes a side).
  constexpr size_t kMostVisited = 5000;
  for (int side = 0; side < 2; ++side) {
    const vdm::TriMat& own = side == 0 ? ta : tb;
    const vdm::NodeMat& x = side == 0 ? xa : xb;
    const vdm::NodeMat& other_x = side == 0 ? xb : xa;
    const vdm::TriMat& other_t = side == 0 ? tb : ta;
    std::vector<std::vector<int>> neighbours(static_cast<size_t>(x.rows()));
    for (Eigen::Index f = 0; f < own.rows(); ++f)
      for (int k = 0; k < 3; ++k) neighbours[static_cast<size_t>(own(f, k))].push_back(own(f, (k + 1) % 3));
    std::vector<char> seen(static_cast<size_t>(x.rows()), 0);
    std::vector<int> queue;
    for (const fcl::Contactd& c : contacts)
      for (int k = 0; k < 3; ++k) {
        const int i = own(side == 0 ? c.b1 : c.b2, k);
        if (!seen[static_cast<size_t>(i)]) seen[static_cast<size_t>(i)] = 1, queue.push_back(i);
      }
    for (size_t q = 0; q < queue.size() && q < kMostVisited; ++q) {
      const int i = queue[q];
      const double d = depth_inside(other_x, other_t, x.row(i).transpose());
      if (!(d > 0)) continue;
      if (d > out.depth) {
        out.depth = d;
        out.node = i;
        out.in_b = side == 0;
        out.where = x.row(i).transpose();
      }
      for (int j : neighbours[static_cast<size_t>(i)])
        if (!seen[static_cast<size_t>(j)]) seen[static_cast<size_t>(j)] = 1, queue.push_back(j);
    }
  }
  return out;
}

}  // namespace vdmsim
