#pragma once
// Keyframes placed on the organ (instruments[].script[].on_surface): each ray is cast against
// the organ's rest surface as placed (after organ.scale, rotate_deg and translate) by the ray
// caster of `vdmsim locate`, and the keyframe gets the tip it names (and, with align, its axis).
#include <vector>

#include "app/scene/scene.hpp"

namespace vdmsim {

// Where a placement landed (m): the surface point, the surface's outward unit normal there,
// and the tip it gave (point - depth * normal).
struct SurfaceHit {
  vdm::Vec3 point = vdm::Vec3::Zero();
  vdm::Vec3 normal = vdm::Vec3::Zero();
  vdm::Vec3 tip = vdm::Vec3::Zero();
};

// Resolves every scene.surface_keyframes entry against `surface` (closed, outward) into its
// keyframe's tip and axis; `hits` gets one entry per placement, in order. A ray that misses the
// surface, or starts inside the organ (it first meets the surface from within), is an error
// at the on_surface key's position; false when there is one.
bool resolve_surface_keyframes(SceneDef& scene, const vdm::SurfaceMesh& surface, std::vector<SurfaceHit>& hits,
                               std::vector<SceneProblem>& problems);

// "instruments[i].script[k]" of a placement, for messages and check's report.
std::string placement_field(const SurfacePlacement& p);

}  // namespace vdmsim
