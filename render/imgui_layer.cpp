#include "render/imgui_layer.hpp"

#include <GL/gl.h>
#include <GL/glext.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
  // The font texture now, and the atlas's CPU copies freed: its RGBA pixels (2 MB: three
  // sizes of DejaVu Sans, oversampled 2x2) and the TTF files it read (3 x 0.7 MB) are not
  // needed once the texture is made (ImGui keeps the glyphs' metrics and UVs).
  if (!ImGui_ImplOpenGL3_CreateDeviceObjects()) {
    error = "ImGui's OpenGL3 backend could not create its shader and font texture";
    return false;
  }
  // The atlas is white with the glyphs' coverage in alpha: one byte a texel (GL_R8 read as
  // (1, 1, 1, r)) instead of ImGui's RGBA, a quarter of llvmpipe's copy.
  unsigned char* alpha = nullptr;
  int w = 0, h = 0;
  io.Fonts->GetTexDataAsAlpha8(&alpha, &w, &h);
  const GLuint tex = static_cast<GLuint>(reinterpret_cast<intptr_t>(io.Fonts->TexID));
  GLint last = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &last);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, w, h, 0, GL_RED, GL_UNSIGNED_BYTE, alpha);
  const GLint swizzle[4] = {GL_ONE, GL_ONE, GL_ONE, GL_RED};
  glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, swizzle);
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(last));
  io.Fonts->ClearTexData();
  io.Fonts->ClearInputData();
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

bool ImGuiLayer::drawn_bounds(int& x0, int& y0, int& x1, int& y1) const {
  ImGui::SetCurrentContext(context_);
  const ImDrawData* data = ImGui::GetDrawData();
  if (!data || !data->Valid) return false;
  float lo_x = 1e30f, lo_y = 1e30f, hi_x = -1e30f, hi_y = -1e30f;
  for (int l = 0; l < data->CmdListsCount; ++l)
    for (const ImDrawVert& v : data->CmdLists[l]->VtxBuffer) {
      lo_x = std::min(lo_x, v.pos.x);
      lo_y = std::min(lo_y, v.pos.y);
      hi_x = std::max(hi_x, v.pos.x);
      hi_y = std::max(hi_y, v.pos.y);
    }
  if (hi_x < lo_x) return false;
  const ImVec2 size = data->DisplaySize;
  x0 = std::max(0, int(std::floor(lo_x)) - 1);
  y0 = std::max(0, int(std::floor(lo_y)) - 1);
  x1 = std::min(int(size.x), int(std::ceil(hi_x)) + 1);
  y1 = std::min(int(size.y), int(std::ceil(hi_y)) + 1);
  return x1 > x0 && y1 > y0;
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
