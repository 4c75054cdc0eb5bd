#pragma once
// render.camera.focus: instruments: the region the automatic camera frames instead of the
// whole organ, the instruments' working area over the script.
#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

// How near the organ's rest surface an instrument counts as working (m): a few radii, at
// least 5 mm.
double working_distance(const InstrumentDef& def);

// The box around the instruments' tips at the times check's geometric pass samples
// (reach_times) when they are within working_distance of the organ's rest surface (every
// sampled tip when none comes that near), padded on every side by the larger of 6 % of the
// organ's size, five instrument radii and twice the deepest tip depth, so that the dent and
// the tissue around it are in view. False when the scene has no instrument.
bool instruments_working_area(const PreparedScene& ps, vdm::Vec3& lo, vdm::Vec3& hi);

// The scene's render settings with the focus box filled in when render.camera.focus is
// instruments (the renderer frames it); as they are otherwise.
render::RenderSettings framed_settings(const PreparedScene& ps);

}  // namespace vdmsim
