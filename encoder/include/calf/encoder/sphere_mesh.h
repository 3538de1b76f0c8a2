// Analytic spheres as triangles. The mesh track holds triangles only, so the mesh encoder
// tessellates every analytic sphere of a scene mesh (SCENE.md "Mesh", `spheres`) into a fixed
// icosphere and appends its triangles after the mesh's own: sphere s of a mesh with T triangles
// is prototype triangles [T + s * kSphereTriangles, T + (s + 1) * kSphereTriangles). The
// visible-set builder (visible_set.h) numbers sphere triangles the same way, so a sphere it finds
// visible is kept whole.
#pragma once

#include <cstdint>
#include <vector>

namespace calf::encoder {

// Subdivisions of the icosahedron: 20 * 4^3 = 1280 triangles, 642 vertices per sphere.
inline constexpr uint32_t kSphereSubdivisions = 3;
inline constexpr uint32_t kSphereTriangles = 20u << (2 * kSphereSubdivisions);
inline constexpr uint32_t kSphereVertices = 10u * (1u << (2 * kSphereSubdivisions)) + 2u;

// Appends one sphere's vertices (3 floats each: positions and unit normals) and triangles
// (counter-clockwise seen from outside, indices offset by the vertices already in `positions`)
// to the arrays (`normals` may be null: no normals). Deterministic: the same sphere gives the
// same floats on every machine.
void append_sphere_mesh(const float centre[3], float radius, std::vector<float>* positions,
                        std::vector<float>* normals, std::vector<uint32_t>* indices);

}  // namespace calf::encoder
