#pragma once
// GLSL 4.50 sources of the renderer's programs (render-internal).
namespace render::shaders {

// Organ and instruments: world-space lighting with a key light, a fill light and a
// sky/ground ambient; instruments cast soft analytic capsule shadows. The fragment source has
// no #version line: the renderer prepends it and MODE_TISSUE, MODE_COLORMAP or MODE_METAL.
extern const char* const kMeshVertex;
extern const char* const kMeshFragment;
// The floor's shadow mask: casters projected along the key light onto the floor plane.
extern const char* const kShadowMaskVertex;
extern const char* const kShadowMaskFragment;
// The floor (with kMeshVertex), fading into the background gradient.
extern const char* const kFloorFragment;
// The background gradient, drawn last at the far plane so that only uncovered pixels pay.
extern const char* const kBackgroundVertex;
extern const char* const kBackgroundFragment;
// The ground-truth pass (render/ground_truth_pass.hpp): each object's id, its camera-space
// normal and its camera z into three targets, unlit.
extern const char* const kGroundTruthVertex;
extern const char* const kGroundTruthFragment;

}  // namespace render::shaders
