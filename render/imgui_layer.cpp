#include "render/imgui_layer.hpp"

#include <GL/gl.h>
#include <GL/glext.h>
#include <imgui_impl_opengl3.h>

#include <filesystem>

namespace render {
namespace {
// DejaVu Sans (Debian's fonts-dejavu-core, installed by setup.sh). Without it ImGui's
// built-in bitmap font is used, scaled.
const char* kFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
const char* kBoldFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
}  // namespace

ImGuiLayer::~ImGuiLayer() {
  if (!context_) return;
  ImGui::SetCurrentContext(context_);
  clear_textures();
  if (backend_) ImGui_ImplOpenGL3_Shutdown();
  ImGui::DestroyContext(context_);
}

bool ImGuiLayer::init(float body_px, std::string& error) {
  context_ = ImGui::CreateContext();
  ImGui::SetCurrentContext(context_);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  io.LogFilename = nullptr;
  io.DisplaySize = ImVec2(16, 16);
  const float sizes[3] = {body_px, std::max(10.0f, body_px * 0.8f), body_px * 1.2f};
  const bool have_font = std::filesystem::exists(kFontPath);
  for (int i = 0; i < 3; ++i) {
    ImFontConfig cfg;
    cfg.OversampleH = 2;
    cfg.OversampleV = 2;
    if (have_font) {
      const char* path = (i == 2 && std::filesystem::exists(kBoldFontPath)) ? kBoldFontPath : kFontPath;
      fonts_[i] = io.Fonts->AddFontFromFileTTF(path, sizes[i], &cfg);
    } else {
      cfg.SizePixels = sizes[i];
      fonts_[i] = io.Fonts->AddFontDefault(&cfg);
    }
  }
  if (!fonts_[0]) {
    error = "ImGui could not load a font";
    return false;
  }
  if (!ImGui_ImplOpenGL3_Init("#version 410 core")) {
    error = "ImGui's OpenGL3 backend failed to initialise";
    return false;
  }
  backend_ = true;
  return true;
}

ImDrawList* ImGuiLayer::begin(int width, int height) {
  ImGui::SetCurrentContext(context_);
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(float(width), float(height));
  io.DisplayFramebufferScale = ImVec2(1, 1);
  io.DeltaTime = 1.0f / 30.0f;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();
  return ImGui::GetForegroundDrawList();
}

void ImGuiLayer::end() {
  ImGui::SetCurrentContext(context_);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

ImFont* ImGuiLayer::font(FontRole role) const { return fonts_[static_cast<int>(role)]; }

ImTextureID ImGuiLayer::texture(const Image& image) {
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  textures_.push_back(tex);
  return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(tex));
}

void ImGuiLayer::clear_textures() {
  if (!textures_.empty()) glDeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
  textures_.clear();
}

ImVec2 text_size(ImFont* font, const std::string& text) {
  return font->CalcTextSizeA(font->FontSize, 1e6f, 0.0f, text.c_str());
}

void draw_text(ImDrawList* dl, ImFont* font, ImVec2 pos, ImU32 colour, const std::string& text) {
  dl->AddText(font, font->FontSize, pos, colour, text.c_str());
}

}  // namespace render
