// Surfel candidates (surfel_candidates.h): orthographic G-buffers of each mesh prototype ray cast
// with Embree, one candidate per hit pixel.
#include "calf/samples/surfel_candidates.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/format/colour.h"

namespace calf::samples {

namespace {

using capture::SceneFile;
using capture::SceneMesh;
using capture::SurfelCandidates;

constexpr unsigned kTriangles = 0, kSpheres = 1;  // Embree geometry ids of a mesh's scene

// One hit pixel before colouring: where, which primitive, and the barycentrics on it.
struct Hit {
  glm::vec3 position, normal;
  uint32_t geometry, primitive;
  float u, v;
};

glm::vec3 vertex(const SceneMesh& m, uint32_t i) {
  return {m.positions[3 * size_t{i}], m.positions[3 * size_t{i} + 1],
          m.positions[3 * size_t{i} + 2]};
}

// An Embree device and the scene of one mesh in object space.
class MeshScene {
 public:
  MeshScene(RTCDevice device, const SceneMesh& mesh) : scene_(rtcNewScene(device)) {
    // Robust: no cracks between triangles sharing an edge (holes in a candidate set).
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    if (mesh.triangle_count() > 0) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, mesh.vertex_count()));
      auto* t = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, mesh.triangle_count()));
      ok_ = v && t;
      if (ok_) {
        std::copy(mesh.positions.begin(), mesh.positions.end(), v);
        std::copy(mesh.indices.begin(), mesh.indices.end(), t);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, kTriangles);
      }
      rtcReleaseGeometry(g);
    }
    if (ok_ && !mesh.spheres.empty()) {
      RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
      auto* b = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, mesh.spheres.size()));
      ok_ = b != nullptr;
      if (ok_) {
        for (size_t i = 0; i < mesh.spheres.size(); ++i) {
          const capture::SceneSphere& s = mesh.spheres[i];
          b[4 * i] = s.center[0], b[4 * i + 1] = s.center[1], b[4 * i + 2] = s.center[2];
          b[4 * i + 3] = s.radius;
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene_, g, kSpheres);
      }
      rtcReleaseGeometry(g);
    }
  }
  ~MeshScene() { rtcReleaseScene(scene_); }
  MeshScene(const MeshScene&) = delete;
  MeshScene& operator=(const MeshScene&) = delete;
  bool ok() const { return ok_; }
  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_;
  bool ok_ = true;
};

// The mesh's box: rest-pose positions and spheres.
void mesh_box(const SceneMesh& mesh, glm::vec3* lo, glm::vec3* hi) {
  *lo = glm::vec3(INFINITY), *hi = glm::vec3(-INFINITY);
  for (size_t i = 0; i < mesh.vertex_count(); ++i) {
    const glm::vec3 p = vertex(mesh, static_cast<uint32_t>(i));
    *lo = glm::min(*lo, p), *hi = glm::max(*hi, p);
  }
  for (const capture::SceneSphere& s : mesh.spheres) {
    const glm::vec3 c(s.center[0], s.center[1], s.center[2]);
    *lo = glm::min(*lo, c - s.radius), *hi = glm::max(*hi, c + s.radius);
  }
  if (!(lo->x <= hi->x)) *lo = *hi = glm::vec3(0);  // nothing at all: a point at the origin
}

// An orthographic view of the box along `d`.
struct View {
  glm::dvec3 start, right, up, dir;  // start: the window's centre on the near plane
  double side = 1, depth = 1;        // window side and ray length, object units
};

View make_view(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& d) {
  View v;
  v.dir = glm::dvec3(d);
  const glm::dvec3 ref = std::fabs(d.y) > 0.999f ? glm::dvec3(0, 0, 1) : glm::dvec3(0, 1, 0);
  v.right = glm::normalize(glm::cross(v.dir, ref));
  v.up = glm::cross(v.right, v.dir);
  const glm::dvec3 c = (glm::dvec3(lo) + glm::dvec3(hi)) * 0.5,
                   h = (glm::dvec3(hi) - glm::dvec3(lo)) * 0.5;
  double extent = 0;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 corner(k & 1 ? h.x : -h.x, k & 2 ? h.y : -h.y, k & 4 ? h.z : -h.z);
    extent =
        std::max({extent, std::fabs(glm::dot(corner, v.right)), std::fabs(glm::dot(corner, v.up))});
  }
  v.side = extent > 0 ? 2 * extent * 1.001 : 1;
  const double radius = glm::length(h);
  const double margin = 0.01 * radius + 1e-4;
  v.start = c - v.dir * (radius + margin);
  v.depth = 2 * (radius + margin);
  return v;
}

// The hits of row `row` of the view, left to right.
void trace_row(RTCScene scene, const SceneMesh& mesh, const View& view, uint32_t resolution,
               uint32_t row, std::vector<Hit>* out) {
  const double step = view.side / resolution;
  const glm::vec3 d(view.dir);
  const glm::dvec3 row_start =
      view.start + view.up * (view.side / 2 - (row + 0.5) * step) - view.right * (view.side / 2);
  for (uint32_t x = 0; x < resolution; ++x) {
    const glm::vec3 o(row_start + view.right * ((x + 0.5) * step));
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tnear = 0;
    rh.ray.tfar = static_cast<float>(view.depth);
    rh.ray.time = 0;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    Hit hit;
    hit.geometry = rh.hit.geomID;
    hit.primitive = rh.hit.primID;
    hit.u = rh.hit.u, hit.v = rh.hit.v;
    if (hit.geometry == kTriangles) {
      const uint32_t* t = &mesh.indices[3 * size_t{hit.primitive}];
      const glm::vec3 a = vertex(mesh, t[0]), b = vertex(mesh, t[1]), c = vertex(mesh, t[2]);
      hit.position = a * (1 - hit.u - hit.v) + b * hit.u + c * hit.v;
      hit.normal = glm::cross(b - a, c - a);
    } else {
      const capture::SceneSphere& s = mesh.spheres[hit.primitive];
      const glm::vec3 centre(s.center[0], s.center[1], s.center[2]);
      hit.normal = o + d * rh.ray.tfar - centre;
      const float l = glm::length(hit.normal);
      hit.position = l > 0 ? centre + hit.normal * (s.radius / l) : o + d * rh.ray.tfar;
    }
    const float l = glm::length(hit.normal);
    hit.normal = l > 0 && std::isfinite(l) ? hit.normal / l : -d;
    if (glm::dot(hit.normal, d) > 0) hit.normal = -hit.normal;  // face the view
    out->push_back(hit);
  }
}

// The colour of `hit` for objects of material `material` (SCENE.md's diffuse reflectance).
glm::vec3 base_colour(const SceneFile& scene, const SceneMesh& mesh, const Hit& hit,
                      uint32_t material) {
  const bool triangle = hit.geometry == kTriangles;
  if (triangle && !mesh.triangle_materials.empty()) {
    material = mesh.triangle_materials[hit.primitive];
  }
  const capture::SceneMaterial& m = scene.materials[material];
  glm::vec3 colour(m.base_color[0], m.base_color[1], m.base_color[2]);
  if (!triangle) return colour;
  const uint32_t* t = &mesh.indices[3 * size_t{hit.primitive}];
  const float w[3] = {1 - hit.u - hit.v, hit.u, hit.v};
  if (m.base_color_texture != capture::kNoTexture && !mesh.uvs.empty()) {
    const capture::SceneTexture& tex = scene.textures[m.base_color_texture];
    if (tex.width > 0 && tex.height > 0 && tex.rgba.size() == size_t{tex.width} * tex.height * 4) {
      float u = 0, v = 0;
      for (int k = 0; k < 3; ++k) {
        u += w[k] * mesh.uvs[2 * size_t{t[k]}];
        v += w[k] * mesh.uvs[2 * size_t{t[k]} + 1];
      }
      auto texel = [](float c, uint32_t n) {
        const double f = std::floor(static_cast<double>(c) * n);
        const double wrapped = std::fmod(f, static_cast<double>(n));
        return static_cast<size_t>(wrapped < 0 ? wrapped + n : wrapped);
      };
      const uint8_t* px = &tex.rgba[(texel(v, tex.height) * tex.width + texel(u, tex.width)) * 4];
      colour *=
          glm::vec3(linear_from_srgb8(px[0]), linear_from_srgb8(px[1]), linear_from_srgb8(px[2]));
    }
  }
  if (!mesh.colors.empty()) {
    glm::vec3 vc(0);
    for (int k = 0; k < 3; ++k) {
      vc += w[k] * glm::vec3(mesh.colors[3 * size_t{t[k]}], mesh.colors[3 * size_t{t[k]} + 1],
                             mesh.colors[3 * size_t{t[k]} + 2]);
    }
    colour *= vc;
  }
  return colour;
}

// The materials the objects placing each mesh use, sorted and unique.
std::vector<std::vector<uint32_t>> materials_per_mesh(const SceneFile& scene) {
  std::vector<std::vector<uint32_t>> out(scene.meshes.size());
  for (const capture::SceneObject& o : scene.objects) {
    if (o.mesh < out.size()) out[o.mesh].push_back(o.material);
  }
  for (auto& m : out) {
    std::sort(m.begin(), m.end());
    m.erase(std::unique(m.begin(), m.end()), m.end());
  }
  return out;
}

class Caster {
 public:
  explicit Caster(const SurfelCandidateOptions& options)
      : options_(options),
        arena_(options.threads == 0 ? tbb::task_arena::automatic
                                    : static_cast<int>(options.threads)) {
    const std::string config =
        options.threads ? "threads=" + std::to_string(options.threads) : std::string();
    device_ = rtcNewDevice(config.c_str());
  }
  ~Caster() {
    if (device_) rtcReleaseDevice(device_);
  }
  Caster(const Caster&) = delete;
  Caster& operator=(const Caster&) = delete;

  // The record of mesh `index`; `after_view` is called after each view.
  template <class AfterView>
  Expected<SurfelCandidates> cast(const SceneFile& scene, uint32_t index,
                                  const std::vector<uint32_t>& materials,
                                  const AfterView& after_view) {
    if (!device_) return Status(ErrorId::kRayTracer, "Embree: cannot create a device");
    const SceneMesh& mesh = scene.meshes[index];
    MeshScene rtc(device_, mesh);
    if (!rtc.ok()) {
      return Status(ErrorId::kRayTracer, "Embree: cannot allocate the buffers of mesh " +
                                             std::to_string(index) + " '" + mesh.name + "'");
    }
    arena_.execute([&] { rtcCommitScene(rtc.get()); });
    glm::vec3 lo, hi;
    mesh_box(mesh, &lo, &hi);
    SurfelCandidates p;
    p.mesh = index;
    p.mesh_hash = capture::surfel_mesh_hash(mesh);
    p.box_min = {lo.x, lo.y, lo.z};
    p.box_max = {hi.x, hi.y, hi.z};
    const uint32_t r = options_.resolution;
    std::vector<Hit> hits;
    std::vector<std::vector<Hit>> rows(r);
    for (const glm::vec3& d :
         surfel_view_directions(lo, hi, options_.directions, options_.corners)) {
      const View view = make_view(lo, hi, d);
      arena_.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, r),
                          [&](const tbb::blocked_range<uint32_t>& b) {
                            for (uint32_t y = b.begin(); y != b.end(); ++y) {
                              rows[y].clear();
                              trace_row(rtc.get(), mesh, view, r, y, &rows[y]);
                            }
                          });
      });
      capture::SurfelCandidateView& v = p.views.emplace_back();
      v.direction = {d.x, d.y, d.z};
      v.pixel_size = static_cast<float>(view.side / r);
      const size_t before = hits.size();
      for (const auto& row : rows) hits.insert(hits.end(), row.begin(), row.end());
      v.candidate_count = static_cast<uint32_t>(hits.size() - before);
      after_view();
    }
    p.positions.resize(3 * hits.size());
    p.normals.resize(3 * hits.size());
    for (size_t i = 0; i < hits.size(); ++i) {
      for (int a = 0; a < 3; ++a) {
        p.positions[3 * i + a] = hits[i].position[a];
        p.normals[3 * i + a] = hits[i].normal[a];
      }
    }
    for (uint32_t material : materials) {
      capture::SurfelColourSet& set = p.colour_sets.emplace_back();
      set.material = material;
      set.colours.resize(3 * hits.size());
      arena_.execute([&] {
        tbb::parallel_for(size_t{0}, hits.size(), size_t{4096}, [&](size_t begin) {
          const size_t end = std::min(hits.size(), begin + 4096);
          for (size_t i = begin; i < end; ++i) {
            const glm::vec3 c = base_colour(scene, mesh, hits[i], material);
            for (int a = 0; a < 3; ++a) set.colours[3 * i + a] = srgb8_from_linear(c[a]);
          }
        });
      });
    }
    rays_ += uint64_t{options_.directions} * r * r;
    return p;
  }
  uint64_t rays() const { return rays_; }

 private:
  SurfelCandidateOptions options_;
  tbb::task_arena arena_;
  RTCDevice device_ = nullptr;
  uint64_t rays_ = 0;
};

}  // namespace

Status validate_surfel_candidate_options(const SurfelCandidateOptions& o) {
  auto bad = [](const std::string& what) { return Status(ErrorId::kSurfelOption, what); };
  if (o.resolution < 1 || o.resolution > capture::kSurfelMaxResolution) {
    return bad("surfel resolution " + std::to_string(o.resolution) + " is outside 1..4096");
  }
  if (o.directions != 8 && o.directions != 16) {
    return bad("surfel directions " + std::to_string(o.directions) + " is neither 8 nor 16");
  }
  if (o.corners != capture::SurfelCorners::kCube && o.corners != capture::SurfelCorners::kBox) {
    return bad("surfel corners " + std::to_string(static_cast<uint32_t>(o.corners)) +
               " is neither cube (0) nor box (1)");
  }
  if (o.threads > 256) return bad("threads " + std::to_string(o.threads) + " is outside 0..256");
  return Status::Ok();
}

std::vector<glm::vec3> surfel_view_directions(const glm::vec3& box_min, const glm::vec3& box_max,
                                              uint32_t directions, capture::SurfelCorners corners) {
  glm::vec3 h = (box_max - box_min) * 0.5f;
  if (corners == capture::SurfelCorners::kCube || !(glm::length(h) > 0)) h = glm::vec3(1);
  std::vector<glm::vec3> out;
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 s(k & 1 ? 1.0f : -1.0f, k & 2 ? 1.0f : -1.0f, k & 4 ? 1.0f : -1.0f);
    out.push_back(glm::normalize(-s * h));
  }
  if (directions == 16) {
    // Turned 45 degrees about +Y: x' = (x + z) / sqrt 2, z' = (z - x) / sqrt 2.
    const float c = 0.70710678f;
    for (int k = 0; k < 8; ++k) {
      const glm::vec3 d = out[k];
      out.push_back(glm::normalize(glm::vec3(c * (d.x + d.z), d.y, c * (d.z - d.x))));
    }
  }
  return out;
}

Expected<capture::SurfelCandidates> surfel_candidates_of_mesh(
    const capture::SceneFile& scene, uint32_t index, const SurfelCandidateOptions& options) {
  CALF_RETURN_IF_ERROR(validate_surfel_candidate_options(options));
  if (index >= scene.meshes.size()) {
    return Status(ErrorId::kSurfelOption,
                  "mesh " + std::to_string(index) + " of " + std::to_string(scene.meshes.size()));
  }
  Caster caster(options);
  return caster.cast(scene, index, materials_per_mesh(scene)[index], [] {});
}

Expected<SurfelCandidateStats> write_surfel_candidates(const capture::SceneFile& scene,
                                                       const SurfelCandidateOptions& options,
                                                       const std::string& path,
                                                       const ProgressFn& progress) {
  const auto start = std::chrono::steady_clock::now();
  CALF_RETURN_IF_ERROR(validate_surfel_candidate_options(options));
  CALF_RETURN_IF_ERROR(capture::validate_scene_file(scene));
  capture::SurfelCandidateHeader header;
  header.scene = scene.name.substr(0, capture::kSurfelMaxSceneName);
  header.resolution = options.resolution;
  header.direction_count = options.directions;
  header.corners = options.corners;
  header.prototype_count = static_cast<uint32_t>(scene.meshes.size());
  auto writer = capture::SurfelCandidateWriter::create(path, header);
  if (!writer.ok()) return writer.status();
  const auto materials = materials_per_mesh(scene);
  Caster caster(options);
  SurfelCandidateStats stats;
  const uint64_t total = uint64_t{options.directions} * scene.meshes.size();
  uint64_t done = 0;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    auto p = caster.cast(scene, m, materials[m], [&] {
      if (progress) progress(++done, total);
    });
    if (!p.ok()) return p.status();
    stats.candidates += p->candidate_count();
    CALF_RETURN_IF_ERROR(writer->add(*p));
  }
  CALF_RETURN_IF_ERROR(writer->commit());
  stats.meshes = scene.meshes.size();
  stats.rays = caster.rays();
  stats.bytes = writer->bytes_written();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace calf::samples
