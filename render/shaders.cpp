#include "render/shaders.hpp"

namespace render::shaders {

const char* const kMeshVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_scalar;
layout(location = 3) in vec3 a_rest;   // the organ's rest position (its texture's coordinates)
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_proj;
uniform vec3 u_key_dir;          // toward the key light
uniform int u_capsules;          // instruments casting soft analytic shadows
uniform vec4 u_capsule_a[4];     // xyz: one end, w: radius
uniform vec4 u_capsule_b[4];     // xyz: the other end
uniform int u_boxes;             // box and convex probes: oriented boxes with rounded edges
uniform vec4 u_box_centre[4];    // xyz: centre, w: edge rounding
uniform vec4 u_box_half[4];      // xyz: half sizes of the core box
uniform mat3 u_box_axes[4];      // columns: the box's axes in the world
uniform float u_world_texture;   // 1: the texture at the world position (the abdomen's wall)
out vec3 v_position;
out vec3 v_normal;
out float v_scalar;
out float v_shadow;
out vec3 v_rest;
#ifdef LIGHT_TIP
uniform sampler3D u_noise;       // render/tissue_texture.hpp
uniform float u_noise_scale;     // its coarse scale: the colour's variation, per vertex
out float v_tint;
#endif
#ifdef MODE_WALL
// The abdomen's wall, lit per vertex (it is smooth, dim and out of focus): its colour, tone
// mapped and in sRGB, for the fragment shader to vignette.
uniform vec3 u_eye;
uniform float u_light_distance;
uniform vec3 u_base_srgb;
uniform vec3 u_second_srgb;
out vec3 v_color;
#endif

// Light reaching p from the key light past the instruments (capsules): the distance from
// the light ray to each capsule's segment gives a soft edge that widens with distance.
float capsule_light(vec3 p) {
  float light = 1.0;
  for (int i = 0; i < u_capsules; ++i) {
    vec3 a = u_capsule_a[i].xyz, b = u_capsule_b[i].xyz;
    float r = u_capsule_a[i].w;
    vec3 ab = b - a, ap = a - p;
    // Closest points between the ray p + t L (t >= 0) and the segment a + s ab.
    float d1 = dot(u_key_dir, u_key_dir), d2 = dot(ab, ab), d3 = dot(u_key_dir, ab);
    float e1 = dot(u_key_dir, ap), e2 = dot(ab, ap);
    float den = d1 * d2 - d3 * d3;
    float s = den > 1e-12 ? clamp((d3 * e1 - d1 * e2) / den, 0.0, 1.0) : 0.0;
    float t = max((dot(u_key_dir, a + s * ab - p)) / d1, 0.0);
    s = clamp(dot(p + t * u_key_dir - a, ab) / max(d2, 1e-12), 0.0, 1.0);
    float dist = length(p + t * u_key_dir - (a + s * ab));
    float soft = 0.3 * r + 0.03 * t;
    light *= mix(0.35, 1.0, smoothstep(r - soft, r + soft, dist));
  }
  return light;
}

// Distance from q to a box of half sizes h centred at the origin (negative inside).
float box_distance(vec3 q, vec3 h) {
  vec3 d = abs(q) - h;
  return length(max(d, 0.0)) + min(max(d.x, max(d.y, d.z)), 0.0);
}

// Light reaching p past the boxes: the smallest distance from the light ray to each box's
// core (convex along the ray, found by golden-section search), less its rounding, gives the
// same soft edge as a capsule's.
float box_light(vec3 p) {
  float light = 1.0;
  vec3 dir = normalize(u_key_dir);
  for (int i = 0; i < u_boxes; ++i) {
    vec3 c = u_box_centre[i].xyz, h = u_box_half[i].xyz;
    float r = u_box_centre[i].w;
    mat3 R = u_box_axes[i];
    vec3 o = transpose(R) * (p - c), l = transpose(R) * dir;
    float reach = length(h) + r;
    float hi = dot(c - p, dir) + reach;
    if (hi <= 0.0) continue;  // the box is behind p, away from the light
    float lo = max(0.0, hi - 2.0 * reach);
    float a = hi - 0.618034 * (hi - lo), b = lo + 0.618034 * (hi - lo);
    float fa = box_distance(o + a * l, h), fb = box_distance(o + b * l, h);
    for (int k = 0; k < 24; ++k) {
      if (fa < fb) { hi = b; b = a; fb = fa; a = hi - 0.618034 * (hi - lo); fa = box_distance(o + a * l, h); }
      else { lo = a; a = b; fa = fb; b = lo + 0.618034 * (hi - lo); fb = box_distance(o + b * l, h); }
    }
    float t = 0.5 * (lo + hi);
    float dist = min(fa, fb) - r;
    float soft = 0.3 * (min(h.x, h.y) + r) + 0.03 * t;
    light *= mix(0.35, 1.0, smoothstep(-soft, soft, dist));
  }
  return light;
}

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_position = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_scalar = a_scalar;
  v_rest = mix(a_rest, world.xyz, u_world_texture);
#ifdef LIGHT_TIP
  v_tint = textureLod(u_noise, v_rest * u_noise_scale, 0.0).a;
#endif
#ifdef MODE_WALL
  vec3 to_eye = u_eye - world.xyz;
  float d = length(to_eye);
  float fall = min(u_light_distance * u_light_distance / max(d * d, 1e-8), 4.0);
  float lit = max(dot(normalize(v_normal), to_eye / d), 0.0);
  vec3 base = mix(u_base_srgb * u_base_srgb, u_second_srgb * u_second_srgb, smoothstep(0.45, 0.8, v_tint));
  vec3 c = base * (1.15 * max((lit + 0.2) / 1.2, 0.0) + 0.05) * fall;
  v_color = sqrt(vec3(1.0) - exp(-1.6 * c));
#endif
  // Per vertex: the organ's mesh is much finer than a shadow's soft edge.
  v_shadow = capsule_light(world.xyz) * box_light(world.xyz);
  gl_Position = u_view_proj * world;
}
)";

const char* const kMeshFragment = R"(
// Compiled once per material with MODE_TISSUE, MODE_COLORMAP or MODE_METAL defined:
// llvmpipe runs every branch of a shader, so each material gets its own small program. With
// LIGHT_TIP (the endoscope) the only light is at the camera, falling off with distance; the
// tissue gets its texture (colour variation, fine bumps, a wet highlight) and every material
// the lens's vignetting. Lighting is done in an approximately linear space (gamma 2: square
// in, square root out).
in vec3 v_position;
in vec3 v_normal;
in float v_scalar;
in float v_shadow;
in vec3 v_rest;
uniform vec3 u_base_srgb;
uniform vec3 u_eye;
uniform vec3 u_key_dir;          // toward the key light
uniform vec3 u_fill_dir;         // toward the fill light
uniform vec2 u_range;            // colour map range
uniform sampler2D u_colormap;    // 256 x 1, sRGB
#ifdef LIGHT_TIP
in float v_tint;                 // the coarse field at the vertices (the colour's variation)
#ifdef MODE_WALL
in vec3 v_color;                 // the wall's, lit per vertex
#endif
uniform float u_light_distance;  // where the light's exposure is set for (m)
uniform vec2 u_viewport;         // width, height (pixels)
uniform sampler3D u_noise;       // render/tissue_texture.hpp: rgb the field's gradient, a the field
uniform float u_noise_scale;     // texture periods per metre of the rest shape (the coarse scale)
uniform vec3 u_second_srgb;      // the tissue's other colour, where the field is high
uniform float u_bump;            // how far the fine field tilts the normal
#endif
out vec4 frag_color;

// x^32 by repeated squaring (cheaper than pow on llvmpipe).
float pow32(float x) { x *= x; x *= x; x *= x; x *= x; return x * x; }

void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(u_eye - v_position);
#ifdef MODE_WALL
  vec2 w = (gl_FragCoord.xy - 0.5 * u_viewport) / (0.5 * length(u_viewport));
  frag_color = vec4(v_color * (1.0 - 0.62 * dot(w, w) * (0.6 + 0.4 * dot(w, w))), 1.0);
  return;
#endif
#ifdef LIGHT_TIP
  // The light is at the lens: it comes from the viewer, and falls off as 1 / d^2, exposed for
  // u_light_distance (a surface there is lit as by a unit light).
  float d = length(u_eye - v_position);
  float fall = min(u_light_distance * u_light_distance / max(d * d, 1e-8), 4.0);
  vec2 q = (gl_FragCoord.xy - 0.5 * u_viewport) / (0.5 * length(u_viewport));
  float vignette = 1.0 - 0.62 * dot(q, q) * (0.6 + 0.4 * dot(q, q));
#ifdef MODE_COLORMAP
  float t = clamp((v_scalar - u_range.x) / max(u_range.y - u_range.x, 1e-30), 0.0, 1.0);
  vec3 c = texture(u_colormap, vec2((t * 255.0 + 0.5) / 256.0, 0.5)).rgb;
  float lit = max(dot(n, v), 0.0);
  float shade = 0.45 + 0.55 * min(lit * fall, 1.2);
  frag_color = vec4(clamp(c * shade * vignette + vec3(0.06 * pow32(lit)), 0.0, 1.0), 1.0);
#else
  vec3 base = u_base_srgb * u_base_srgb;
  vec3 color;
#ifdef MODE_TISSUE
  vec3 second = u_second_srgb * u_second_srgb;
  base = mix(base, second, smoothstep(0.45, 0.8, v_tint));
  // Fine bumps: the field at a finer scale tilts the normal (one fetch a pixel).
  vec4 fine = textureLod(u_noise, v_rest * (u_noise_scale * 9.7), 0.0);  // no mipmaps: level 0, no derivatives
  vec3 g = fine.rgb * 2.0 - 1.0;
  n = normalize(n - u_bump * (g - dot(g, n) * n));
  base *= 0.9 + 0.2 * fine.a;
  float lit = max(dot(n, v), 0.0);
  float wrap = max((lit + 0.2) / 1.2, 0.0);
  float crease = 1.0 - v_scalar;   // v_scalar: how deep in a crease (0 on open surface)
  // A wet layer: a sharp bright highlight where the surface faces the lens, a faint broad one.
  float wet = pow32(lit);
  wet *= wet;
  color = (base * (1.15 * wrap + 0.05) * crease + vec3(0.55) * wet + vec3(0.05) * pow32(sqrt(lit)) * crease) * fall;
#else
  // Brushed steel under the tip light.
  float lit = max(dot(n, v), 0.0);
  color = (base * (0.9 * lit + 0.06) + vec3(0.7) * pow32(lit) * pow32(lit)) * fall;
#endif
  // A soft shoulder instead of clipping: the tip light over-exposes what comes close.
  color = vec3(1.0) - exp(-1.6 * color);
  frag_color = vec4(sqrt(clamp(color, 0.0, 1.0)) * vignette, 1.0);
#endif
#else
  float shadow = v_shadow;
  float key = max(dot(n, u_key_dir), 0.0);
  float fill = max(dot(n, u_fill_dir), 0.0);
  float nh = max(dot(n, normalize(u_key_dir + v)), 0.0);
#ifdef MODE_COLORMAP
  // Colour map: the map's colours stay readable, shading only modulates them.
  float t = clamp((v_scalar - u_range.x) / max(u_range.y - u_range.x, 1e-30), 0.0, 1.0);
  vec3 c = texture(u_colormap, vec2((t * 255.0 + 0.5) / 256.0, 0.5)).rgb;
  float shade = 0.62 + 0.30 * key * shadow + 0.10 * fill;
  frag_color = vec4(clamp(c * shade + vec3(0.08 * pow32(nh) * shadow), 0.0, 1.0), 1.0);
#else
  float sky = 0.5 + 0.5 * n.z;
  vec3 base = u_base_srgb * u_base_srgb;
  vec3 color;
#ifdef MODE_TISSUE
  // Tissue: wrapped diffuse (light bleeds past the terminator), a moist highlight, a faint rim.
  float wrap = max((dot(n, u_key_dir) + 0.35) / 1.35, 0.0);
  float rim = 1.0 - max(dot(n, v), 0.0);
  vec3 ambient = mix(vec3(0.10, 0.08, 0.08), vec3(0.20, 0.20, 0.23), sky);
  color = base * (1.25 * wrap * shadow + 0.35 * fill + ambient * 1.6);
  float nh2 = nh * nh;
  color += vec3(0.22) * pow32(nh) * shadow + vec3(0.04) * (nh2 * nh2 * nh2) * shadow;
  color += base * 0.30 * rim * rim * rim;
#else
  // Brushed steel.
  vec3 ambient = mix(vec3(0.10), vec3(0.30), sky);
  float fh = max(dot(n, normalize(u_fill_dir + v)), 0.0);
  color = base * (1.0 * key * shadow + 0.45 * fill + ambient);
  color += vec3(0.8) * pow32(nh) * pow32(nh) * shadow + vec3(0.12) * pow32(fh);
#endif
  frag_color = vec4(sqrt(clamp(color, 0.0, 1.0)), 1.0);
#endif
#endif
}
)";

const char* const kShadowMaskVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_model;
uniform mat4 u_floor_proj;   // world -> along the key light onto the floor -> mask texture
void main() { gl_Position = u_floor_proj * u_model * vec4(a_position, 1.0); }
)";

const char* const kShadowMaskFragment = R"(#version 450 core
out vec4 frag_color;
void main() { frag_color = vec4(0.0); }
)";

const char* const kFloorFragment = R"(#version 450 core
// The floor, drawn as a square under the organ after it (so covered pixels cost nothing): lit
// by the sky, darkened by the shadow mask, fading into the background gradient with distance.
in vec3 v_position;
uniform vec3 u_top_srgb;
uniform vec3 u_bottom_srgb;
uniform float u_height;          // viewport height (pixels)
uniform vec3 u_floor_center;
uniform float u_floor_radius;
uniform float u_mask_half;       // half size of the shadow mask's square on the floor
uniform int u_floor_shadow;
uniform sampler2D u_mask;        // 1 lit, 0 in shadow; mipmapped
out vec4 frag_color;
void main() {
  vec3 background = mix(u_bottom_srgb, u_top_srgb, gl_FragCoord.y / u_height);
  vec2 d = v_position.xy - u_floor_center.xy;
  float fade = smoothstep(0.30 * u_floor_radius, u_floor_radius, length(d));
  float lit = u_floor_shadow != 0 ? textureLod(u_mask, d / (2.0 * u_mask_half) + 0.5, 1.6).r : 1.0;
  frag_color = vec4(mix(vec3(0.74, 0.74, 0.75) * mix(0.55, 1.0, lit), background, fade), 1.0);
}
)";

const char* const kBackgroundVertex = R"(#version 450 core
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  gl_Position = vec4(p, 1.0, 1.0);   // at the far plane: drawn only where nothing else is
}
)";

const char* const kBackgroundFragment = R"(#version 450 core
uniform vec3 u_top_srgb;
uniform vec3 u_bottom_srgb;
uniform float u_height;
out vec4 frag_color;
void main() { frag_color = vec4(mix(u_bottom_srgb, u_top_srgb, gl_FragCoord.y / u_height), 1.0); }
)";

const char* const kGroundTruthVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_proj;
uniform mat4 u_view;     // world -> OpenGL's camera space (x right, y up, z backward)
out vec3 v_camera;       // the point in OpenGL's camera space
out vec3 v_normal;       // its normal there
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_camera = (u_view * world).xyz;
  v_normal = mat3(u_view) * (u_normal_matrix * a_normal);
  gl_Position = u_view_proj * world;
}
)";

const char* const kGroundTruthFragment = R"(#version 450 core
// Camera z is affine over a triangle, so its perspective-correct interpolation is the z of the
// surface point seen through the pixel's centre. Outputs in OpenCV's camera axes (x right,
// y down, z forward).
in vec3 v_camera;
in vec3 v_normal;
uniform uint u_id;
layout(location = 0) out uint out_id;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out float out_depth;
void main() {
  out_id = u_id;
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  out_normal = vec4(0.5 * vec3(n.x, -n.y, -n.z) + 0.5, 1.0);
  out_depth = -v_camera.z;
}
)";

}  // namespace render::shaders
