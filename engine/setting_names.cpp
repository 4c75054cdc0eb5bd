// The names of the engine's settings as scene files and run.json write them (ModelKind,
// SolverMethod, CapsuleForm): apart from the solvers they name, so that a reader of scene files
// (the sweep fuzzer) links these without the engine.
#include <string>

#include "engine/organ_solver.hpp"
#include "engine/settings.hpp"
#include "engine/tissue_model.hpp"

namespace vdm {

const char* to_string(ModelKind k) {
  switch (k) {
    case ModelKind::vdm: return "vdm";
    case ModelKind::fem: return "fem";
    case ModelKind::mass_spring: return "mass_spring";
    case ModelKind::vdm_core: return "vdm_core";
  }
  return "unknown";
}

bool parse_model_kind(const std::string& t, ModelKind& out) {
  if (t == "vdm") out = ModelKind::vdm;
  else if (t == "fem") out = ModelKind::fem;
  else if (t == "mass_spring") out = ModelKind::mass_spring;
  else if (t == "vdm_core") out = ModelKind::vdm_core;
  else return false;
  return true;
}

const char* to_string(SolverMethod m) {
  switch (m) {
    case SolverMethod::reference: return "reference";
    case SolverMethod::structured: return "structured";
    case SolverMethod::direct: return "direct";
  }
  return "unknown";
}

bool parse_solver_method(const std::string& text, SolverMethod& out) {
  if (text == "reference" || text == "bicgstab") out = SolverMethod::reference;
  else if (text == "structured" || text == "cg") out = SolverMethod::structured;
  else if (text == "direct" || text == "cholesky") out = SolverMethod::direct;
  else return false;
  return true;
}

const char* to_string(CapsuleForm c) {
  switch (c) {
    case CapsuleForm::membrane: return "membrane";
    case CapsuleForm::corotational: return "corotational";
    case CapsuleForm::paper: return "paper";
  }
  return "unknown";
}

bool parse_capsule_form(const std::string& text, CapsuleForm& out) {
  if (text == "membrane") out = CapsuleForm::membrane;
  else if (text == "corotational") out = CapsuleForm::corotational;
  else if (text == "paper") out = CapsuleForm::paper;
  else return false;
  return true;
}

}  // namespace vdm
