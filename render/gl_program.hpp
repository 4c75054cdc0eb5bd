#pragma once
// A linked GLSL program from vertex and fragment sources, with compile errors as text.
#include <string>

namespace render {

class GlProgram {
 public:
  GlProgram() = default;
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;
  // Compiles and links; false with the driver's log in `error`.
  bool build(const char* vertex_source, const char* fragment_source, std::string& error);
  unsigned id() const { return id_; }
  // Deletes the program (its driver memory goes with it); id() is 0 until built again.
  void reset();
  int uniform(const char* name) const;  // location, -1 when absent

 private:
  unsigned id_ = 0;
};

}  // namespace render
