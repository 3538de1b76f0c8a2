// What the mesh renderers draw (paper 004 playback): a plain list of prototype meshes in object
// space and of objects placing them, each with a rigid transform, a material and the subset of
// the prototype's triangles it draws. MeshRepresentation (mesh_representation.h) fills one from a
// mesh track (calf/decoder/mesh_track.h) at each frame; tests build one directly.
//
// Both renderers — the OpenGL 4.5 rasteriser (GlMeshRenderer, the product) and the scalar CPU
// rasteriser (render_mesh_cpu, the reference it is tested against), mesh_renderer.h — draw a list
// with exactly the rules below, and produce what every representation produces (rendered_image.h):
// linear colour plus the radial distance from the eye centre to the surface each pixel shows, +inf
// where nothing is drawn (colour 0 there), so Playback composites a mesh with a light field.
//
// Geometry. A vertex's world position is transform * (x, y, z, 1) with the row-major 3 x 4
// transform (as SCENE.md and decoder::MeshTransform). A pixel (i, j) shows the nearest triangle
// whose projection covers the pixel centre (i + 0.5, j + 0.5) (the camera model of
// calf/format/camera.h); coverage of a centre on an edge follows the top-left rule in image
// coordinates (row 0 at the top), so triangles sharing an edge never both cover, nor both miss, a
// centre on it. Only the part of a triangle farther than MeshRenderOptions::near along the
// camera's forward axis is drawn (near-plane clipping); there is no far plane. Triangles are drawn
// from both sides (no back-face culling). Depth ties keep the first drawn (objects in list order,
// triangles in increasing index order).
//
// Shading (deterministic, identical in both renderers up to float rounding and the texture
// footprint, below):
//   colour = base * texture * vertex_colour * (kMeshAmbient + (1 - kMeshAmbient) * max(0, n . L))
//            + emission
// with L = kMeshKeyLight (a unit vector towards a fixed key light, world space), base and emission
// the triangle's material (the object's, or the prototype's per-triangle material when it has
// them and it is not kMeshObjectMaterial), vertex_colour the prototype's colours interpolated
// perspective-correctly (1 when it has none), and n the unit normal facing the eye's side of the
// triangle: the prototype's vertex normals transformed by the transform's inverse transpose and
// interpolated perspective-correctly, or the face normal normalize((p1 - p0) x (p2 - p0)) when the
// prototype has none; flipped when the triangle's front (the side (p1 - p0) x (p2 - p0) points to)
// faces away from the eye.
//
// Texture: 1 unless the triangle's material has a base-colour texture and the prototype has UVs;
// then the texture's linear RGB (alpha is not used: surfaces are opaque) at the UV interpolated
// perspective-correctly, filtered trilinearly as GL's LINEAR_MIPMAP_LINEAR with REPEAT wrapping
// on the texture's mip chain (calf/format/mesh_texture.h; sRGB decoded per texel before
// filtering): bilinear on level floor(lambda) and floor(lambda) + 1, blended by the fraction,
// with lambda = log2(rho) clamped to [0, levels - 1] and rho = max(|d(uv * size)/dx|,
// |d(uv * size)/dy|) (Euclidean lengths); lambda <= 0 is magnification: bilinear on level 0. UV
// (0, 0) is texel (0, 0)'s corner at the image's top-left; texel (i, j)'s centre is
// ((i + 0.5) / w, (j + 0.5) / h). The derivatives are those of the 2 x 2 pixel quad the pixel is
// in (pixels (2a, 2b) .. (2a + 1, 2b + 1)): d/dx from its top pair, d/dy from its left pair, the
// UVs there taken on the triangle's plane (also outside the triangle) — GL's coarse derivatives,
// which llvmpipe computes; a GPU may pick fine derivatives or approximate rho and pick a nearby
// level (the renderer test measures how far the two agree).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "calf/format/mesh_lighting.h"
#include "calf/format/mesh_texture.h"
#include "calf/format/status.h"

namespace calf::player {

// The fixed key light and the ambient share of the shading (calf/format/mesh_lighting.h).
using mesh::kMeshAmbient;
using mesh::kMeshKeyLight;

// A per-triangle material of this value takes the object's material (as the mesh track's
// mesh::kObjectMaterial: an analytic sphere's triangles in a mesh with per-triangle materials).
inline constexpr uint32_t kMeshObjectMaterial = 0xffffffffu;

// A material without a texture.
inline constexpr uint32_t kMeshNoTexture = 0xffffffffu;

// A surface: linear diffuse reflectance, emitted radiance and a base-colour texture.
struct MeshDrawMaterial {
  std::array<float, 3> base_colour{0.7f, 0.7f, 0.7f};
  std::array<float, 3> emission{0, 0, 0};
  uint32_t base_colour_texture = kMeshNoTexture;  // index into MeshDrawList::textures
};

// A mesh in object space. `positions` are those at the frame being drawn (MeshRepresentation puts
// the vertex states at the frame's time there).
struct MeshDrawPrototype {
  std::vector<float> positions;   // 3 per vertex
  std::vector<float> normals;     // empty (face normals) or 3 per vertex
  std::vector<float> colours;     // empty (white) or 3 per vertex, linear
  std::vector<float> uvs;         // empty (untextured) or 2 per vertex, v = 0 at the top row
  std::vector<uint32_t> indices;  // 3 per triangle, each < vertex count
  // Empty (every triangle takes its object's material) or 1 per triangle: an index into
  // MeshDrawList::materials, or kMeshObjectMaterial for the object's.
  std::vector<uint32_t> triangle_materials;

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// A placed prototype.
struct MeshDrawObject {
  uint32_t prototype = 0;
  // Row-major 3 x 4 object-to-world transform; invertible (a rigid motion, possibly scaled).
  std::array<float, 12> transform{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  uint32_t material = 0;  // index into MeshDrawList::materials
  // true: every triangle of the prototype; false: only `triangles` (prototype triangle indices,
  // strictly increasing; empty draws nothing).
  bool all_triangles = true;
  std::vector<uint32_t> triangles;
  // false: the object is skipped (the surfel representation draws it as surfels this frame). Not
  // part of the structure a GL upload fixes: it may change between renders.
  bool visible = true;

  // How many triangles this object draws when visible.
  size_t drawn_triangles(const MeshDrawPrototype& p) const {
    return all_triangles ? p.triangle_count() : triangles.size();
  }
};

struct MeshDrawList {
  std::vector<MeshDrawPrototype> prototypes;
  std::vector<MeshDrawObject> objects;
  std::vector<MeshDrawMaterial> materials;
  // Each texture as its whole mip chain (mesh::mip_chain of the track's texture).
  std::vector<std::vector<mesh::TextureTexels>> textures;
};

// Options both renderers take.
struct MeshRenderOptions {
  // The near clipping distance along the camera's forward axis, in scene units: > 0 and finite.
  double near = 0.01;
};

// CALF-E470 unless `list` is drawable, naming the first fault: a buffer whose length is not a
// multiple of 3 or not one per vertex / triangle, a vertex index, material index, prototype index
// or subset triangle out of range, a subset not strictly increasing, a non-finite position,
// normal, colour, UV, material value or transform, a transform whose 3 x 3 part is singular, a
// material texture out of range, or a texture that is not a whole mip chain (level sizes as
// mesh_texture.h, 4 bytes per texel).
// Materials' colours must be finite and >= 0. Both renderers call it.
[[nodiscard]] Status validate_mesh_draw_list(const MeshDrawList& list);

// CALF-E471 unless `options` are valid (near > 0 and finite).
[[nodiscard]] Status validate_mesh_render_options(const MeshRenderOptions& options);

// The number of triangles `list` draws (every visible object's subset) — the "triangles drawn"
// figure.
// `list` must be valid.
uint64_t mesh_draw_triangle_count(const MeshDrawList& list);

}  // namespace calf::player
