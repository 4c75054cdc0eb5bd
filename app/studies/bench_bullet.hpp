#pragma once
// The Bullet side of `vdmsim bench` (performance issue): Bullet's btSoftBody on the same
// closed surface as a VDM case, with pressure (kPR) and volume conservation (kVC) on, fixed
// where the scene fixes the organ, pushed by a kinematic capsule that follows the scene's
// probe script frame by frame. Built only when CMake finds Bullet (VDMSIM_HAVE_BULLET).
#include <memory>
#include <string>
#include <vector>

#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

// Bullet's knobs as the bench sets them, tuned on the liver probe case (2.5k and 10k nodes)
// for Bullet's best volume at a stable step:
// - 60 Hz (Bullet's usual step), 2 per 30 Hz frame; 4 position iterations (default 1);
// - kPR on but small: Bullet's links are position constraints that 4 iterations hold only
//   loosely, so a pressure that matters inflates the body (1 Pa: +4 to +7 % volume);
// - kVC as a modulus: 5 kPa per unit of relative volume loss keeps the volume within about
//   1e-4; 10 kPa and more blows up at 60 Hz (the force is explicit).
struct BulletSettings {
  int substeps = 2;           // Bullet steps per scene frame (dt = frame dt / substeps)
  int piterations = 4;        // position (link) solver iterations per Bullet step
  double link_stiffness = 1;  // kLST of the links (edges), [0, 1]
  double pressure_pa = 0.01;  // kPR = pressure_pa V_0 (Bullet's pressure is kPR / V) (Pa)
  // kVC: Bullet's volume force per node is kVC (V_0 - V) |A_i| along its normal, a pressure
  // kVC (V_0 - V): kVC = volume_modulus / V_0 makes it volume_modulus times the relative loss.
  double volume_modulus = 5000;  // Pa
  double damping = 0.05;      // kDP, [0, 1]
  double contact_hardness = 1;      // kCHR, [0, 1]
  double margin = 0.0005;     // soft body collision margin (m)
  double sdf_voxel = 0.002;   // sparse SDF cell of the rigid probe (m); Bullet's default 0.25 is coarser than the organ
};

struct BulletRun {
  long nodes = 0;
  std::vector<double> step_ms;   // timed frames (in contact, after warm-up): all substeps of the frame
  double volume_rel_error = 0;   // max over all frames of |V - V_0| / V_0 of the deformed surface
  int iterations = 0;            // position-solver iterations per frame (substeps x piterations)
  int contact_frames = 0;        // frames where the probe touched the surface
  double max_displacement = 0;   // largest node displacement from rest over the run (m)
};

// True when this build links Bullet.
bool bullet_available();

// Bullet's soft body on a probe scene, advanced one scene frame at a time, so that the bench
// can interleave its frames with VDM's (both then see the same machine load, frame by frame).
// Throws std::runtime_error when Bullet is not built in, or when the scene has no probe.
class BulletProbe {
 public:
  BulletProbe(const PreparedScene& ps, const BulletSettings& settings);
  ~BulletProbe();
  BulletProbe(const BulletProbe&) = delete;
  BulletProbe& operator=(const BulletProbe&) = delete;
  // Scene frame f (its substeps, the probe moved along its script): the wall time of the
  // Bullet steps alone (ms). Then, untimed: the deformed surface's volume and the contact.
  double advance(int f);
  bool touching() const;                 // the probe touched the surface in the last frame
  double volume_rel_error() const;       // |V - V_0| / V_0 after the last frame
  double max_displacement() const;       // the largest node displacement from rest so far (m)
  long nodes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Runs `ps` (a probe scene) for `frames` frames with Bullet. Frames are timed when the probe
// touches the organ and `f > warmup`. Throws std::runtime_error when Bullet is not built in.
BulletRun run_bullet_probe(const PreparedScene& ps, int frames, int warmup, const BulletSettings& settings);

// One line describing the settings, for the bench's output and the README.
std::string describe(const BulletSettings& s);

}  // namespace vdmsim
