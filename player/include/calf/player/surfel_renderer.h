// The two splatters of a surfel draw list (surfel_draw_list.h states what they draw): the OpenGL
// 4.5 one (the product) and the scalar CPU one (the reference it is tested against,
// tests/player/surfel_renderer_test.cc).
//
// CPU (render_surfels_cpu): per surfel, the disc's bounding parallelogram (centre ± r u ± r v in
// world space) goes to the camera's frame, is clipped against the near plane and projected; for
// every pixel centre inside its projected bounds the ray (calf::camera_ray) meets the disc's
// plane, the hit is written as centre + a U + b V (U, V the world images of r u, r v) and kept when
// a² + b² <= 1, it lies beyond the near plane and is strictly nearer than what the pixel holds.
//
// GL (GlSurfelRenderer): one vertex array per prototype (positions, normals, colours; uploaded
// once); per object one glDrawArrays(GL_POINTS, 0, prefix) with its transform and radius as
// uniforms. A geometry shader turns each point into the disc's bounding parallelogram in world
// space (two triangles in the disc's plane, so rasterisation and depth are those of the plane
// itself, with no point-size limit: llvmpipe caps point sprites at 255 px, and near discs are
// larger); the fragment shader discards outside a² + b² <= 1 (a, b interpolated
// perspective-correctly), shades as the mesh does and writes the radial distance. Depth test:
// reversed Z with an infinite far plane, GL_GREATER (first drawn wins ties), as the mesh renderer.
#pragma once

#include <GL/glcorearb.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/rendered_image.h"
#include "calf/player/surfel_draw_list.h"

namespace calf::player {

namespace internal {
class GlRasterTarget;
}

// Renders `list` for `camera` into `out` (resized to the camera's image). Errors: CALF-E474 for
// an invalid list, CALF-E475 for invalid options, CALF-E403 for an invalid camera. Deterministic.
Status render_surfels_cpu(const SurfelDrawList& list, const Camera& camera,
                          const SurfelRenderOptions& options, RenderedImage* out);

// The GL splatter. All calls need the GL context of `gl` current on the calling thread.
class GlSurfelRenderer {
 public:
  // Compiles the shaders. Errors: CALF-E404 when a shader does not compile or link.
  static Expected<std::unique_ptr<GlSurfelRenderer>> make(const GlFunctions& gl);
  ~GlSurfelRenderer();
  GlSurfelRenderer(const GlSurfelRenderer&) = delete;
  GlSurfelRenderer& operator=(const GlSurfelRenderer&) = delete;

  // Uploads every prototype's surfels (replacing an earlier upload). Errors: CALF-E474, CALF-E412.
  Status upload(const SurfelDrawList& list);

  // Draws `list` — whose prototypes must be those of the last upload (count and surfels per
  // prototype), CALF-E476 otherwise; objects (transforms, prefixes, radii) are read from `list` at
  // each call — for `camera` into `out`. Errors: CALF-E403, CALF-E474, CALF-E475, CALF-E476,
  // CALF-E412.
  Status render(const SurfelDrawList& list, const Camera& camera,
                const SurfelRenderOptions& options, RenderedImage* out);

 private:
  explicit GlSurfelRenderer(const GlFunctions& gl);
  void release_buffers();

  struct PrototypeBuffers {
    GLuint vao = 0, positions = 0, normals = 0, colours = 0;
    uint32_t surfel_count = 0;
  };
  const GlFunctions* gl_;
  GLuint program_ = 0;
  std::vector<PrototypeBuffers> prototypes_;
  std::unique_ptr<internal::GlRasterTarget> target_;
};

}  // namespace calf::player
