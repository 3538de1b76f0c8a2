// Private to the player: reading a rendered frame back from the bound framebuffer, shared by the
// light-field ray-marcher (lightfield_gl_renderer.cc) and the mesh rasteriser
// (mesh_gl_renderer.cc). Both draw into an RGBA32F colour attachment 0 holding linear RGB and
// radial depth.
#pragma once

#include <cstddef>
#include <vector>

#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/rendered_image.h"

namespace calf::player::internal {

// Reads `width` x `height` RGBA floats from colour attachment 0 of the bound framebuffer into
// `out` (colour = RGB, depth = A; GL's bottom-up rows turned so that row 0 is the top), then
// binds the default framebuffer. `what` names the step in a GL error (CALF-E412).
inline Status read_back_colour_and_depth(const GlFunctions& gl, uint32_t width, uint32_t height,
                                         const char* what, RenderedImage* out) {
  const size_t w = width, h = height;
  std::vector<float> rgba(4 * w * h);
  gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl.PixelStorei(GL_PACK_ROW_LENGTH, 0);
  gl.PixelStorei(GL_PACK_SKIP_PIXELS, 0);
  gl.PixelStorei(GL_PACK_SKIP_ROWS, 0);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.ReadPixels(0, 0, static_cast<GLsizei>(w), static_cast<GLsizei>(h), GL_RGBA, GL_FLOAT,
                rgba.data());
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (Status s = check_gl_error(gl, what); !s.ok()) return s;
  out->width = width;
  out->height = height;
  out->color.resize(3 * w * h);
  out->depth.resize(w * h);
  for (size_t j = 0; j < h; ++j) {
    const float* row = &rgba[4 * w * (h - 1 - j)];
    for (size_t i = 0; i < w; ++i) {
      const size_t k = j * w + i;
      for (int ch = 0; ch < 3; ++ch) out->color[3 * k + ch] = row[4 * i + ch];
      out->depth[k] = row[4 * i + 3];
    }
  }
  return Status::Ok();
}

}  // namespace calf::player::internal
