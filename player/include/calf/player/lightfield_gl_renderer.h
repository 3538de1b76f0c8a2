// The OpenGL 4.5 ray-march renderer of paper 002 Alg. 4 (and its RR variant, Sec. 6.1): the
// player's product renderer. It implements exactly the algorithm of the scalar CPU reference
// (calf/player/lightfield_cpu_renderer.h, docs/RENDERING.md): the same LightfieldRenderOptions, the
// same Camera model, the same texel taps, footprint test, coverage test, refinement, weights, sky
// and RR rules — one GLSL function per CPU function — and is tested against it
// (tests/integration/lightfield_gl_renderer_test.cc: PSNR between the two images of the same frame
// >= 45 dB).
//
// It reads the viewpoint textures of a GlViews (calf/player/gl_views.h), which the decoder's
// LightfieldFrameUpdates (or updates_from_view_set()) fill; a cell's colour is the keyframe blend
// mix(slot a, slot 1 - a, t / 255) done per texel in the shader. Views with coverage faces
// answer LightfieldRenderOptions::coverage and coverage_agreement as the CPU's do; the coverage
// test is compiled into the shader only when some view of the GlViews has coverage.
//
// A frame is one full-screen fragment pass into a framebuffer object holding RGBA32F: rgb the
// linear colour (HDR kept), alpha the radial distance from the eye to the surface (+inf for sky),
// read back into the CPU renderer's RenderedImage so the two compare directly.
//
// Differences from the CPU reference, all below the test's bound: the GPU computes in float (the
// CPU in double), in coordinates relative to the eye (so precision does not depend on where the
// scene sits); the RR variant walks its ray tree with an explicit stack instead of recursion (the
// sum is the same, its order differs). Images are deterministic for a given driver. Isolated rays
// can differ where float and double fall on different sides of a threshold decision (a hint
// crossing confirmed by its margin, the view that weighs most); tests/integration bound both.
//
// All calls need the GL context of the GlViews to be current.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "calf/format/status.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_cpu_renderer.h"

namespace calf::player {

namespace internal {
class GlRasterTarget;
}

// march_range_for() of lightfield_cpu_renderer.h for a GL texture layout: far = max_j(|eye - P_j| +
// z_far_j), near = min_j z_near_j / 4 but no nearer
// than far / 2^20 (a tiny z_near must not stretch the log steps). Errors: CALF-E403 for no views.
Expected<LightfieldRenderOptions> march_range_for(const GlTextureLayout& layout, const Vec3& eye,
                                                  LightfieldRenderOptions options);

class LightfieldGlRenderer {
 public:
  // Compiles the shaders for `views` (which must outlive the renderer) and validates `options`
  // as LightfieldCpuRenderer::make does (CALF-E403 naming the option; `threads` is ignored).
  // Errors: CALF-E404 when a shader does not compile or link (the driver's log follows).
  static Expected<std::unique_ptr<LightfieldGlRenderer>> make(
      const GlViews& views, const LightfieldRenderOptions& options);
  ~LightfieldGlRenderer();
  LightfieldGlRenderer(const LightfieldGlRenderer&) = delete;
  LightfieldGlRenderer& operator=(const LightfieldGlRenderer&) = delete;

  // New options for the next frames (march range, weights, ...). Nothing is recompiled,
  // except when surface_hints changes: the hint count is compiled into the shader (its per-hint
  // state then stays in registers; llvmpipe's first frame after it pays the compile, ~2 s).
  // Errors as make(); the old options (and program) stay on error.
  Status set_options(const LightfieldRenderOptions& options);
  const LightfieldRenderOptions& options() const { return options_; }

  // Renders `camera` with the frame's `active_views` (indices into the layout's views, in any
  // order; empty = every view) into `out` (resized): colour and radial distance per pixel, row 0
  // at the top, as LightfieldCpuRenderer::render. Errors: CALF-E403 for an invalid camera (as the
  // CPU renderer) or active view (validate_active_views, or more than the shader's view block
  // holds), CALF-E412 when GL reports an error, CALF-E404 when the driver ended some pixel's
  // march loops early (llvmpipe's loop limit; the image is not usable).
  Status render(const Camera& camera, std::span<const uint32_t> active_views, RenderedImage* out);
  Status render(const Camera& camera, RenderedImage* out) { return render(camera, {}, out); }

  // Draws `camera` with `active_views` (as render()) into the framebuffer bound to
  // GL_DRAW_FRAMEBUFFER, viewport (0, 0, width, height) of the camera, output 0 = (rgb, radial
  // distance): for a player that composites the result itself. With supersample > 1 it draws
  // one pass per eye ray and blends them (rgb added, distance the minimum), so output 0 must be
  // a float target holding (0, 0, 0, +inf). A pixel whose march loops the driver ended early gets
  // distance -1 (render() refuses such an image). Leaves program, textures and buffer bindings
  // changed.
  Status draw(const Camera& camera, std::span<const uint32_t> active_views = {});

 private:
  LightfieldGlRenderer(const GlViews& views, const LightfieldRenderOptions& options);
  Status build_program();

  const GlViews* views_;
  const GlFunctions* gl_;
  LightfieldRenderOptions options_;
  GLuint program_ = 0, vao_ = 0, view_buffer_ = 0;
  std::unique_ptr<internal::GlRasterTarget> target_;  // made on the first render()
};

}  // namespace calf::player
