// Private to the player: the off-screen target every GL renderer draws into — an RGBA32F colour
// texture (linear RGB, radial depth in alpha) with, for the rasterisers, a 32-bit float depth
// buffer — recreated only when the image size changes, and read back as a RenderedImage.
#pragma once

#include <cmath>
#include <string>

#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/rendered_image.h"
#include "gl_errors.h"
#include "gl_frame_readback.h"

namespace calf::player::internal {

class GlRasterTarget {
 public:
  // `with_depth`: also a DEPTH_COMPONENT32F attachment (the rasterisers' reversed-Z test).
  GlRasterTarget(const GlFunctions& gl, bool with_depth) : gl_(&gl), with_depth_(with_depth) {}
  ~GlRasterTarget() {
    const GlFunctions& gl = *gl_;
    if (fbo_ != 0) gl.DeleteFramebuffers(1, &fbo_);
    if (colour_ != 0) gl.DeleteTextures(1, &colour_);
    if (depth_ != 0) gl.DeleteTextures(1, &depth_);
  }
  GlRasterTarget(const GlRasterTarget&) = delete;
  GlRasterTarget& operator=(const GlRasterTarget&) = delete;

  // Makes the target `width` x `height` (kept when the size is unchanged), binds its framebuffer,
  // sets the viewport and draw buffer and clears colour to (0, 0, 0, +inf) and depth to 0 (the
  // far end of reversed Z). `what` names the renderer in errors: CALF-E404 when the framebuffer
  // is not complete, CALF-E412 for a GL error.
  Status bind_and_clear(uint32_t width, uint32_t height, const char* what) {
    const GlFunctions& gl = *gl_;
    if (colour_ == 0 || width != width_ || height != height_) {
      CALF_RETURN_IF_ERROR(create(width, height, what));
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    const GLenum buffer = GL_COLOR_ATTACHMENT0;
    gl.DrawBuffers(1, &buffer);
    gl.Viewport(0, 0, static_cast<GLsizei>(width), static_cast<GLsizei>(height));
    const float clear_colour[4] = {0, 0, 0, INFINITY};
    gl.ClearBufferfv(GL_COLOR, 0, clear_colour);
    if (with_depth_) {
      const float clear_depth = 0;
      gl.ClearBufferfv(GL_DEPTH, 0, &clear_depth);
    }
    return check_gl_error(gl, what);
  }

  // Reads the bound target back into `out` (read_back_colour_and_depth) and binds the default
  // framebuffer.
  Status read_back(const char* what, RenderedImage* out) const {
    return read_back_colour_and_depth(*gl_, width_, height_, what, out);
  }

 private:
  Status create(uint32_t width, uint32_t height, const char* what) {
    const GlFunctions& gl = *gl_;
    if (colour_ != 0) gl.DeleteTextures(1, &colour_);
    if (depth_ != 0) gl.DeleteTextures(1, &depth_);
    colour_ = depth_ = 0;
    if (fbo_ == 0) gl.GenFramebuffers(1, &fbo_);
    const auto w = static_cast<GLsizei>(width), h = static_cast<GLsizei>(height);
    gl.GenTextures(1, &colour_);
    gl.BindTexture(GL_TEXTURE_2D, colour_);
    gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    if (with_depth_) {
      gl.GenTextures(1, &depth_);
      gl.BindTexture(GL_TEXTURE_2D, depth_);
      gl.TexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, w, h);
    }
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour_, 0);
    if (with_depth_) {
      gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_, 0);
    }
    const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    CALF_RETURN_IF_ERROR(check_gl_error(gl, what));
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      gl.DeleteTextures(1, &colour_);  // the next call tries again
      if (depth_ != 0) gl.DeleteTextures(1, &depth_);
      colour_ = depth_ = 0;
      return Status(kGlMissing, std::string(what) + ": an RGBA32F" +
                                    (with_depth_ ? " + DEPTH32F" : "") + " framebuffer of " +
                                    std::to_string(width) + " x " + std::to_string(height) +
                                    " is not complete");
    }
    width_ = width;
    height_ = height;
    return Status::Ok();
  }

  const GlFunctions* gl_;
  bool with_depth_;
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
  uint32_t width_ = 0, height_ = 0;
};

}  // namespace calf::player::internal
