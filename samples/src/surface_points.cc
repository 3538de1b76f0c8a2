// Area-uniform points on a scene's surfaces (surface_points.h).
#include "surface_points.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace calf::samples {

namespace {

// A counter-based generator (splitmix64's finaliser): the same numbers for the same (seed,
// index, stream), in any order.
double uniform(uint64_t seed, uint64_t index, uint64_t stream) {
  uint64_t z =
      seed * 0x9E3779B97F4A7C15ull + index * 0xBF58476D1CE4E5B9ull + stream * 0x94D049BB133111EBull;
  z ^= z >> 30;
  z *= 0xBF58476D1CE4E5B9ull;
  z ^= z >> 27;
  z *= 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0);  // [0, 1)
}

// The triangles of one mesh at one time, with the running sum of their areas.
struct MeshAreas {
  const std::vector<glm::uvec3>* triangles = nullptr;
  std::vector<glm::vec3> positions;
  std::vector<double> cumulative;  // cumulative[t] = area of triangles 0..t
  double area() const { return cumulative.empty() ? 0 : cumulative.back(); }
};

MeshAreas mesh_areas(const TriangleMesh& mesh, double time, const glm::mat4* transform) {
  MeshAreas m;
  m.triangles = &mesh.triangles;
  positions_at(mesh, time, &m.positions);
  if (transform) {
    for (glm::vec3& p : m.positions) p = glm::vec3(*transform * glm::vec4(p, 1));
  }
  m.cumulative.reserve(mesh.triangles.size());
  double sum = 0;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::vec3 e1 = m.positions[t.y] - m.positions[t.x];
    const glm::vec3 e2 = m.positions[t.z] - m.positions[t.x];
    sum += 0.5 * static_cast<double>(glm::length(glm::cross(e1, e2)));
    m.cumulative.push_back(sum);
  }
  return m;
}

// A piece of surface: an object's triangles (own or a shared mesh's, placed by `transform`) or
// one sphere.
struct Piece {
  const MeshAreas* mesh = nullptr;  // null: a sphere
  bool shared = false;              // mesh positions are object space, placed by `transform`
  glm::mat4 transform{1};           // shared meshes only (own meshes are already in world space)
  double scale2 = 1;                // the transform's area scale (shared meshes)
  glm::vec3 center{0};
  float radius = 0;
};

size_t find(const std::vector<double>& cumulative, double u) {
  const size_t i = static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                                       cumulative.begin());
  return std::min(i, cumulative.size() - 1);
}

}  // namespace

SurfacePoints sample_surface_points(const Scene& scene, double time, uint32_t count,
                                    uint64_t seed) {
  // Shared meshes once (keyed by pointer; pointers only find, never order, so the result does
  // not depend on them), own meshes transformed to world space.
  std::unordered_map<const TriangleMesh*, MeshAreas> shared;
  std::vector<MeshAreas> own;
  own.reserve(scene.objects.size());
  std::vector<Piece> pieces;
  std::vector<double> cumulative;
  double sum = 0;
  auto add = [&](const Piece& p, double area) {
    if (!(area > 0) || !std::isfinite(area)) return;
    sum += area;
    pieces.push_back(p);
    cumulative.push_back(sum);
  };
  for (const Object& o : scene.objects) {
    const glm::mat4 m = o.transform ? o.transform(time) : glm::mat4(1);
    const double scale = std::cbrt(std::fabs(static_cast<double>(glm::determinant(glm::mat3(m)))));
    if (o.shared_mesh) {
      auto it = shared.find(o.shared_mesh.get());
      if (it == shared.end()) {
        it = shared.emplace(o.shared_mesh.get(), mesh_areas(*o.shared_mesh, time, nullptr)).first;
      }
      Piece p;
      p.mesh = &it->second;
      p.shared = true;
      p.transform = m;
      p.scale2 = scale * scale;
      add(p, it->second.area() * p.scale2);
      continue;
    }
    if (!o.mesh.triangles.empty()) {
      own.push_back(mesh_areas(o.mesh, time, &m));
      Piece p;
      p.mesh = &own.back();
      add(p, own.back().area());
    }
    for (const Sphere& s : o.spheres) {
      Piece p;
      p.center = glm::vec3(m * glm::vec4(s.center, 1));
      p.radius = static_cast<float>(s.radius * scale);
      add(p, 4 * M_PI * static_cast<double>(p.radius) * p.radius);
    }
  }
  SurfacePoints out;
  out.area = sum;
  if (!(sum > 0) || count == 0) return out;
  out.positions.reserve(count);
  for (uint32_t i = 0; i < count; ++i) {
    const double u = (i + uniform(seed, i, 0)) / count * sum;
    const size_t k = find(cumulative, u);
    const Piece& p = pieces[k];
    const double a = uniform(seed, i, 1), b = uniform(seed, i, 2);
    if (!p.mesh) {
      // Uniform on the sphere: z uniform in [-1, 1], longitude uniform.
      const double z = 1 - 2 * a, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * M_PI * b;
      out.positions.push_back(
          p.center + p.radius * glm::vec3(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z)));
      continue;
    }
    // The same stratified number picks the triangle within the piece.
    const MeshAreas& mesh = *p.mesh;
    const double start = k ? cumulative[k - 1] : 0;
    const double within = std::clamp((u - start) / (cumulative[k] - start), 0.0, 1.0);
    const glm::uvec3& t = (*mesh.triangles)[find(mesh.cumulative, within * mesh.area())];
    // Uniform in the triangle: the square-root warp of (a, b).
    const double s = std::sqrt(a);
    const float w1 = static_cast<float>(s * (1 - b)), w2 = static_cast<float>(s * b);
    glm::vec3 q =
        mesh.positions[t.x] * (1 - w1 - w2) + mesh.positions[t.y] * w1 + mesh.positions[t.z] * w2;
    if (p.shared) q = glm::vec3(p.transform * glm::vec4(q, 1));
    out.positions.push_back(q);
  }
  return out;
}

}  // namespace calf::samples
