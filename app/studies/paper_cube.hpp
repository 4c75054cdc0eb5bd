#pragma once
// The paper's cube experiments (vdm-model.md section 9): 4.1 stress distribution under
// compression and 4.2 anisotropy. A cube of side `side` sits on a table (bottom face fixed)
// and a frictionless plate pushes its top face down by `compression` x side over `steps`.
#include <string>
#include <vector>

#include "engine/settings.hpp"
#include "engine/tissue_model.hpp"
#include "engine/types.hpp"

namespace vdmsim {

enum class AnisotropyCase { uniform, x_infinite, prefer_y };
const char* to_string(AnisotropyCase c);

struct CubeCompression {
  double side = 0.1;           // m
  int cells = 8;               // grid cells per cube edge
  double compression = 0.3;    // final plate travel / side
  int steps = 30;              // quasi-static steps to reach it
  double bulk = 20000.0;       // Pa
  double connectivity = 2000.0;  // Pa
  vdm::CapsuleForm capsule = vdm::CapsuleForm::paper;  // the paper's experiments as published
  double preferred_ratio = 0.25;  // prefer_y: B^y = ratio x B
  vdm::SolverSettings solver = default_solver();
  static vdm::SolverSettings default_solver();
};

struct PointSeries {
  std::string name;            // "A", "B", "C"
  int node = -1;               // mesh node tracked
  vdm::Vec3 rest;              // its rest position (m)
  std::vector<vdm::Vec3> displacement;  // per step, step 0 = rest (m)
  std::vector<vdm::Vec3> stress;        // per step, per axis (Pa)
};

struct CubeResult {
  std::vector<PointSeries> points;
  std::vector<double> volume_rel_error;  // per step
  std::vector<double> pressure;          // per step (Pa)
  std::vector<int> iterations;           // per step
};

// 4.1: points A, B, C on the face y = -side/2 (an xz-plane), at heights +side/4, 0, -side/4.
CubeResult run_cube_stress(const CubeCompression& config);
// 4.2: A at the centre of the top face (under the plate), B at the centre of the face
// y = -side/2 (an xz-plane), C at the centre of the face x = +side/2 (a yz-plane).
CubeResult run_anisotropy(const CubeCompression& config, AnisotropyCase which);

// CSV writers; return false with a message naming the file on failure.
bool write_cube_stress_csv(const std::string& path, const CubeResult& r, std::string& error);
bool write_anisotropy_csv(const std::string& path, const std::vector<AnisotropyCase>& cases,
                          const std::vector<CubeResult>& results, std::string& error);

}  // namespace vdmsim
