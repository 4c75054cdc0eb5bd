#pragma once
// The ties of a scene's attachments (engine/organ_pair_contact.hpp): for each attachment, each
// node of its first organ within `within` of its second organ's rest surface, held to the point
// of that surface nearest it, by a spring of the attachment's stiffness per area times the
// node's share of its organ's surface area.
#include <vector>

#include "app/simulation/prepared_scene.hpp"
#include "engine/organ_pair_contact.hpp"

namespace vdmsim {

// The stiffness per area an attachment's ties have (Pa/m): its own, or by default a layer of
// connective tissue `within` thick as stiff as the softer of its organs (E / within).
double attachment_stiffness(const SceneDef& scene, const AttachmentDef& a);

// Every attachment's ties, in attachment order; `per_attachment` (when given) gets how many
// each has.
std::vector<vdm::OrganTie> organ_ties(const PreparedScene& ps, std::vector<int>* per_attachment = nullptr);

}  // namespace vdmsim
