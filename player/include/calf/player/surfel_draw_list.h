// What the surfel renderers draw (paper 001 playback): per prototype a surfel buffer in object
// space, ordered so that every prefix is a level of detail, and objects placing a prototype with a
// rigid transform, each drawing a prefix of its prototype's buffer with a disc radius. The surfel
// representation fills one at each frame (the prefix from each object's projected size, the radius
// from the frame budget); tests build one directly.
//
// Both renderers — the OpenGL 4.5 splatter (GlSurfelRenderer, the product) and the scalar CPU one
// (render_surfels_cpu, the reference it is tested against), surfel_renderer.h — draw a list with
// exactly the rules below, and produce what every representation produces (rendered_image.h):
// linear colour plus the radial distance from the eye centre to the surface each pixel shows, +inf
// where nothing is drawn (colour 0 there), so Playback composites surfels with a mesh or a light
// field.
//
// Geometry: oriented discs. Surfel i of an object with transform T (row-major 3 x 4, 3 x 3 part M)
// and radius r is the image under T of the object-space disc centred at p_i, normal to n_i, of
// radius r: the set T(p_i + r (a u + b v)) with a² + b² <= 1, where (u, v) = surfel_tangents(n_i)
// below. Under a scaled transform it is an ellipse, exactly. A pixel (i, j) shows the nearest disc
// that the ray through its centre (i + 0.5, j + 0.5) (calf/format/camera.h) meets at a point
// farther than SurfelRenderOptions::near along the camera's forward axis; a disc seen exactly
// edge-on covers nothing. Depth ties keep the first drawn (objects in list order, surfels in
// buffer order).
//
// Shading, as the mesh's (mesh_draw_list.h) with the surfel's colour as base colour and its normal
// (M's inverse transpose times n_i, normalised, flipped to face the eye):
//   colour = tint * c_i * (kMeshAmbient + (1 - kMeshAmbient) * max(0, n . kMeshKeyLight)).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::player {

// A prototype's surfels in object space, in level-of-detail order.
struct SurfelDrawPrototype {
  std::vector<float> positions;  // 3 per surfel
  std::vector<float> normals;    // 3 per surfel, unit length (±1e-3)
  std::vector<float> colours;    // 3 per surfel, linear, >= 0

  size_t surfel_count() const { return positions.size() / 3; }
};

// A placed prototype drawing a prefix of its surfels.
struct SurfelDrawObject {
  uint32_t prototype = 0;
  // Row-major 3 x 4 object-to-world transform; its 3 x 3 part invertible.
  std::array<float, 12> transform{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  uint32_t count = 0;   // the prefix drawn: 0 .. the prototype's surfel count
  float radius = 0.0f;  // disc radius in object-space units: > 0 and finite when count > 0
  // Multiplies every surfel colour of this object (linear, finite, >= 0): the object's material
  // base colour when the prototype's colours are relative to it (SPEC §11.3.2), else 1.
  std::array<float, 3> tint{1, 1, 1};
};

struct SurfelDrawList {
  std::vector<SurfelDrawPrototype> prototypes;
  std::vector<SurfelDrawObject> objects;
};

struct SurfelRenderOptions {
  // The near clipping distance along the camera's forward axis, in scene units: > 0 and finite.
  double near = 0.01;
};

// The disc's spanning directions for a unit normal n: u = normalize(n x e) with e the coordinate
// axis least aligned with n (x on ties, then y), v = n x u. The GLSL twin in surfel_gl_renderer.cc
// computes the same.
void surfel_tangents(const Vec3& n, Vec3* u, Vec3* v);

// CALF-E474 unless `list` is drawable, naming the first fault: buffers of different lengths or
// not multiples of 3, a prototype index or prefix count out of range, a non-finite position,
// normal, colour, tint or transform, a normal not of unit length, a negative colour or tint, a
// transform whose
// 3 x 3 part is singular, a radius not > 0 and finite on an object drawing surfels.
[[nodiscard]] Status validate_surfel_draw_list(const SurfelDrawList& list);

// CALF-E475 unless `options` are valid (near > 0 and finite).
[[nodiscard]] Status validate_surfel_render_options(const SurfelRenderOptions& options);

// The surfels `list` draws (the objects' prefixes). `list` must be valid.
uint64_t surfel_draw_count(const SurfelDrawList& list);

}  // namespace calf::player
