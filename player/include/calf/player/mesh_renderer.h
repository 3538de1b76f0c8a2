// The two rasterisers of a mesh draw list (mesh_draw_list.h states what they draw): the OpenGL
// 4.5 one (the product) and the scalar CPU one (the reference it is tested against,
// tests/player/mesh_renderer_test.cc: colour PSNR >= 45 dB between the two, depth equal but at
// triangle edges, where the GPU's fixed-point snapping of vertices may decide a pixel centre on
// the other side).
//
// CPU (render_mesh_cpu): per triangle, the vertices go to eye-relative world space in double, are
// clipped against the near plane (a polygon of up to 4 vertices, fanned into triangles), and
// projected to image coordinates; a pixel centre is covered when all three edge functions are
// positive, or zero on a top or left edge (the top-left rule: edge functions evaluated in double,
// exactly as written in mesh_cpu_renderer.cc). The covered pixel's ray (calf::camera_ray) meets the
// triangle's plane at radial distance t (perspective-correct by construction); barycentric
// coordinates of that point interpolate the attributes; the pixel keeps the triangle when t is
// strictly nearer than what it holds.
//
// GL (GlMeshRenderer): one vertex array per prototype (positions, normals and colours each a buffer
// uploaded once; positions re-uploaded when the caller says they changed), one index buffer per
// prototype and one per object drawing a subset, a storage buffer of materials and of each
// prototype's triangle materials / object's subset (so a primitive finds its prototype triangle);
// one glDrawElements per object and texture its triangles use, with its transform as a uniform
// (the geometry shader drops the triangles of another texture's pass; so depth ties between
// triangles of different textures in one object keep the pass drawn first: ascending texture
// index, untextured last — the CPU keeps the lower triangle index). Each texture is an
// SRGB8_ALPHA8 array texture of one layer holding the mip chain of calf/format/mesh_texture.h,
// sampled LINEAR_MIPMAP_LINEAR with REPEAT. A geometry shader makes the face
// normal and the side the eye sees; the fragment shader shades with the formula of
// mesh_draw_list.h and writes the radial distance of the interpolated eye-relative position.
// Depth test: reversed Z into a 32-bit float depth buffer with an infinite far plane
// (glClipControl zero-to-one; depth = near / z), GL_GREATER, so the first drawn wins ties as on the
// CPU. The frame goes to an RGBA32F target (rgb colour, alpha radial depth; cleared to 0 and +inf)
// read back into a RenderedImage.
#pragma once

#include <GL/glcorearb.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/mesh_draw_list.h"
#include "calf/player/rendered_image.h"

namespace calf::player {

namespace internal {
class GlRasterTarget;
}

// Renders `list` for `camera` into `out` (resized to the camera's image). Errors: CALF-E470 for an
// invalid list, CALF-E471 for invalid options, CALF-E403 for an invalid camera. Deterministic.
Status render_mesh_cpu(const MeshDrawList& list, const Camera& camera,
                       const MeshRenderOptions& options, RenderedImage* out);

// The GL rasteriser. All calls need the GL context of `gl` current on the calling thread.
class GlMeshRenderer {
 public:
  // Compiles the shaders. Errors: CALF-E404 when a shader does not compile or link.
  static Expected<std::unique_ptr<GlMeshRenderer>> make(const GlFunctions& gl);
  ~GlMeshRenderer();
  GlMeshRenderer(const GlMeshRenderer&) = delete;
  GlMeshRenderer& operator=(const GlMeshRenderer&) = delete;

  // Uploads every buffer of `list` (replacing what an earlier upload held): prototypes' vertices
  // and indices, objects' subsets, materials. Errors: CALF-E470 (invalid list), CALF-E412.
  Status upload(const MeshDrawList& list);
  // Re-uploads the positions of prototype `prototype` of `list` (its vertex states moved). The
  // list must have the structure of the last upload: CALF-E472 otherwise.
  Status update_positions(const MeshDrawList& list, uint32_t prototype);
  // Re-uploads the material table (a change of colours between frames).
  Status update_materials(const MeshDrawList& list);

  // Draws `list` — which must have the structure of the last upload (prototype, vertex, triangle
  // and object counts, each object's prototype and subset size), CALF-E472 otherwise; transforms
  // and materials are read from `list` at each call — for `camera` into `out`. Errors: CALF-E403
  // (camera), CALF-E471 (options), CALF-E472, CALF-E412 (GL).
  Status render(const MeshDrawList& list, const Camera& camera, const MeshRenderOptions& options,
                RenderedImage* out);

 private:
  explicit GlMeshRenderer(const GlFunctions& gl);
  Status build_program();
  Status check_structure(const MeshDrawList& list) const;
  void release_buffers();

  struct PrototypeBuffers {
    GLuint vao = 0, positions = 0, normals = 0, colours = 0, indices = 0, triangle_materials = 0,
           uvs = 0;
    uint32_t vertex_count = 0, triangle_count = 0;
    bool has_normals = false, has_colours = false, has_triangle_materials = false, has_uvs = false;
    std::vector<uint32_t> used_materials;  // distinct triangle materials (object's: sentinel)
  };
  struct ObjectBuffers {
    GLuint indices = 0, triangles = 0;  // 0 when the object draws all its prototype's triangles
    uint32_t prototype = 0, drawn = 0;
    bool all_triangles = true;
  };
  // The per-object uniforms' locations, looked up once after linking.
  struct ObjectUniforms {
    GLint model_x = -1, model_y = -1, model_z = -1, model_t = -1;
    GLint normal_x = -1, normal_y = -1, normal_z = -1;
    GLint has_normals = -1, has_triangle_materials = -1, has_subset = -1, object_material = -1;
    GLint has_uvs = -1, pass_texture = -1;
  };
  const GlFunctions* gl_;
  GLuint program_ = 0, materials_ = 0;
  ObjectUniforms uniforms_;
  std::vector<PrototypeBuffers> prototypes_;
  std::vector<ObjectBuffers> objects_;
  size_t material_count_ = 0;
  std::vector<uint32_t> material_textures_;  // each material's texture, as last uploaded
  std::vector<GLuint> textures_;             // one array texture per list texture
  std::unique_ptr<internal::GlRasterTarget> target_;
};

}  // namespace calf::player
