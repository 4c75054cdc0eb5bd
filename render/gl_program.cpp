#include "render/gl_program.hpp"

#include <GL/gl.h>
#include <GL/glext.h>

#include <vector>

namespace render {
namespace {

unsigned compile(GLenum type, const char* source, std::string& error) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint n = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &n);
    std::vector<char> log(static_cast<size_t>(n) + 1, 0);
    glGetShaderInfoLog(shader, n, nullptr, log.data());
    error = std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") + " shader: " + log.data();
    glDeleteShader(shader);
    return 0;
  }
  return shader;
}

}  // namespace

GlProgram::~GlProgram() { reset(); }

void GlProgram::reset() {
  if (id_) glDeleteProgram(id_);
  id_ = 0;
}

bool GlProgram::build(const char* vertex_source, const char* fragment_source, std::string& error) {
  const unsigned vs = compile(GL_VERTEX_SHADER, vertex_source, error);
  if (!vs) return false;
  const unsigned fs = compile(GL_FRAGMENT_SHADER, fragment_source, error);
  if (!fs) {
    glDeleteShader(vs);
    return false;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  // Detached, the shader objects are deleted now rather than with the program: the linked
  // program does not need them, and each kept its compiled form (about 1 MB) otherwise.
  glDetachShader(id_, vs);
  glDetachShader(id_, fs);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint n = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &n);
    std::vector<char> log(static_cast<size_t>(n) + 1, 0);
    glGetProgramInfoLog(id_, n, nullptr, log.data());
    error = std::string("link: ") + log.data();
    return false;
  }
  return true;
}

int GlProgram::uniform(const char* name) const { return glGetUniformLocation(id_, name); }

}  // namespace render
