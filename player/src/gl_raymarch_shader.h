// Private to the player: the GLSL sources of the ray-march renderer (gl_raymarch_shader.cc).
#pragma once

namespace calf::player::internal {

// A full-screen triangle from gl_VertexID (no vertex buffers).
extern const char* const kGlFullscreenVertex;

// Alg. 4 as the CPU reference implements it (lightfield_cpu_renderer.cc,
// lightfield_cpu_renderer_rr.cc), one function per CPU function. Pasted after "#version 450 core",
// "#define CALF_MAX_VIEWS <kGlMaxActiveViews>", an optional "#define CALF_DEPTH_BC5", "#define
// CALF_HINTS <n>", an optional
// "#define CALF_COVERAGE" (some view has coverage faces) and kGlslConventions.
extern const char* const kGlRaymarchFragment;

// The most views one frame can use (the uniform block holds this many records: 16 KiB, the
// smallest GL_MAX_UNIFORM_BLOCK_SIZE GL 4.5 allows).
inline constexpr unsigned kGlMaxActiveViews = 256;

// std140 layout of one active view in the shader's view block (struct CalfView there).
struct GlViewRecord {
  float position[3];  // P_j relative to the eye
  float log_near;     // ln z_near        } the view's GlslLogRange (glsl_log_range()), which the
  float step;         // ln depth per code } shader hands to the conventions' depth functions as
  float inv_step;     // 1 / step          } a CalfLogRange
  float z_near, z_far;
  unsigned face_size;
  unsigned cell_size;
  unsigned layer;      // 6 * view index: depth / cells layer of face 0
  int material_layer;  // 6 * material index, -1 without material
  int coverage_layer;  // 6 * coverage index, -1 without coverage
  int padding[3];      // std140 rounds the struct up to 16 bytes
};
static_assert(sizeof(GlViewRecord) == 64, "must match the std140 struct in the shader");

}  // namespace calf::player::internal
