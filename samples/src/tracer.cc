// The Embree ray tracer: scene build at one time, shading, cube-map and perspective rendering.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <vector>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/format/colour.h"
#include "calf/format/cube.h"
#include "calf/samples/pixel_samples.h"
#include "calf/samples/render.h"
#include "calf/samples/texture.h"
#include "glm_vec.h"

namespace calf::samples {

namespace {

constexpr float kPi = 3.14159265358979f;
// Keeps colour inside half range (the capture format stores half).
constexpr float kMaxRadiance = 65504.0f;

// splitmix64's finaliser: a good 64-bit mix, the base of every random number here.
uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// A counter-based stream: the same key gives the same numbers on every thread and every run.
// With `net` set (spp > 1) ambient occlusion takes its directions from the pixel's scrambled
// (0, 2)-sequence instead: sample s of the pixel uses points [s * ao_samples, (s + 1) *
// ao_samples), so the AO rays of all the pixel's samples at a surface are one stratified set;
// each AO evaluation along the sample's path (the primary surface, then what mirrors and glass
// show) has its own scramble, the same for every sample of the pixel.
struct Rng {
  uint64_t state;
  bool net = false;
  uint64_t net_key = 0;    // the pixel's key
  uint32_t net_index = 0;  // the sample's first sequence point
  uint32_t net_calls = 0;  // AO evaluations so far along this sample's path
  explicit Rng(uint64_t key) : state(mix64(key)) {}
  float uniform() {  // [0, 1)
    state += 0x9E3779B97F4A7C15ull;
    return static_cast<float>(mix64(state) >> 40) * (1.0f / 16777216.0f);
  }
};

uint64_t pixel_key(uint64_t seed, uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  uint64_t k = mix64(seed + 0x632BE59BD9B4E019ull);
  for (uint64_t v : {a, b, c, d}) k = mix64(k ^ (v + 0x9E3779B97F4A7C15ull));
  return k;
}

// An orthonormal basis around n (Duff et al. 2017, branchless).
void basis(const glm::vec3& n, glm::vec3* t, glm::vec3* b) {
  float s = std::copysign(1.0f, n.z);
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  *t = glm::vec3(1 + s * n.x * n.x * a, s * c, -s * n.x);
  *b = glm::vec3(c, s + n.y * n.y * a, -n.y);
}

// One geometry of the top-level Embree scene: an object's triangles or spheres in world space, or
// an instance of a shared mesh (a prototype).
struct Geometry {
  uint32_t material = 0;
  bool spheres = false;
  std::vector<glm::vec3> positions;  // world space at the frame's time
  std::vector<glm::uvec3> triangles;
  std::vector<glm::vec2> uvs;    // own triangles' UVs, kept only when the material is textured
  std::vector<glm::vec4> balls;  // world centre + radius
  // An instance: its prototype (index into Impl::prototypes) and the matrix taking the
  // prototype's face normals to world normals (the transform's 3 x 3 part, negated when it
  // mirrors, which flips the winding).
  int32_t prototype = -1;
  glm::mat3 normal_matrix{1.0f};
};

// A shared mesh built once per frame into its own Embree scene, instanced by every object that
// places it. Holding the mesh keeps the tracer valid after the scene is gone, as for own meshes.
struct Prototype {
  std::shared_ptr<const TriangleMesh> mesh;
  std::vector<glm::vec3> positions;  // object space at the frame's time (vertex states applied)
  RTCScene scene = nullptr;
};

bool finite3(const glm::vec3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// Attaches `positions` / `triangles` to `scene` as one triangle geometry with id `id`.
Status attach_triangles(RTCDevice device, RTCScene scene, unsigned id,
                        const std::vector<glm::vec3>& positions,
                        const std::vector<glm::uvec3>& triangles) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles.size()));
  if (!v || !idx) {
    rtcReleaseGeometry(geom);
    return Status(ErrorId::kRayTracer, "Embree: cannot allocate buffers");
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    v[3 * i] = positions[i].x, v[3 * i + 1] = positions[i].y, v[3 * i + 2] = positions[i].z;
  }
  for (size_t i = 0; i < triangles.size(); ++i) {
    idx[3 * i] = triangles[i].x, idx[3 * i + 1] = triangles[i].y, idx[3 * i + 2] = triangles[i].z;
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  return Status::Ok();
}

RTCScene new_scene(RTCDevice device) {
  RTCScene scene = rtcNewScene(device);
  // Robust mode: no cracks between triangles sharing an edge (stray sky pixels would be depth +inf
  // holes in the middle of a wall).
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  return scene;
}

struct LightAt {
  glm::vec3 position, intensity;
};

struct Hit {
  float t = 0;
  uint32_t geom = 0, prim = 0;
  float u = 0, v = 0;  // Embree's barycentrics: the point is (1 - u - v) p0 + u p1 + v p2
};

// A ray cone (Akenine-Moeller et al. 2019): its width at the ray's origin and its spread angle.
// A primary ray starts at width 0 with its pixel's angular width (pixel_spread); a mirror or glass
// bounce continues from the width reached, with the same spread (surfaces treated as flat). The
// width at a hit picks the texture's mip level.
struct Cone {
  float width = 0;
  float spread = 0;
};

}  // namespace

struct FrameTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene rtc = nullptr;
  std::vector<Geometry> geometries;
  std::vector<Prototype> prototypes;
  std::vector<Material> materials;
  std::vector<std::shared_ptr<const Texture>> textures;
  std::vector<LightAt> lights;
  Sky sky;
  glm::vec3 sun_dir{0, 1, 0};
  glm::vec3 ambient{0};
  float ao_distance = 1;
  LightfieldRenderOptions options;

  ~Impl() {
    if (rtc) rtcReleaseScene(rtc);
    for (Prototype& p : prototypes) {
      if (p.scene) rtcReleaseScene(p.scene);
    }
    if (device) rtcReleaseDevice(device);
  }

  bool intersect(const glm::vec3& o, const glm::vec3& d, float tnear, float tfar, Hit* hit,
                 uint64_t* rays) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = 0;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rtc, &ctx, &rh);
    ++*rays;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit->t = rh.ray.tfar;
    // An instance hit names the instance (a top-level geometry) in instID and the prototype's
    // own geometry (always 0) in geomID.
    hit->geom = rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
    hit->prim = rh.hit.primID;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return true;
  }

  bool occluded(const glm::vec3& o, const glm::vec3& d, float tfar, uint64_t* rays) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray;
    ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
    ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
    ray.tnear = 0;
    ray.tfar = tfar;
    ray.time = 0;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(rtc, &ctx, &ray);
    ++*rays;
    return ray.tfar < 0;  // Embree sets tfar to -inf on a hit
  }

  // Outward geometric normal (unit) of a hit at point p.
  glm::vec3 normal(const Hit& h, const glm::vec3& p) const {
    const Geometry& g = geometries[h.geom];
    if (g.spheres) return glm::normalize(p - glm::vec3(g.balls[h.prim]));
    glm::vec3 n;
    if (g.prototype >= 0) {
      const Prototype& pr = prototypes[static_cast<size_t>(g.prototype)];
      const glm::uvec3& t = pr.mesh->triangles[h.prim];
      n = g.normal_matrix *
          glm::cross(pr.positions[t.y] - pr.positions[t.x], pr.positions[t.z] - pr.positions[t.x]);
    } else {
      const glm::uvec3& t = g.triangles[h.prim];
      n = glm::cross(g.positions[t.y] - g.positions[t.x], g.positions[t.z] - g.positions[t.x]);
    }
    float len = glm::length(n);
    return len > 0 ? n / len : glm::vec3(0, 1, 0);
  }

  // The diffuse reflectance at hit `h` of a ray along unit `d`: the material's albedo times its
  // base-colour texture, trilinearly filtered at the footprint of a cone `cone_width` wide at the
  // hit (texture.h). Untextured materials, spheres and meshes without UVs give the albedo.
  glm::vec3 albedo_at(const Hit& h, const Material& m, const glm::vec3& d, float cone_width) const {
    if (m.base_color_texture >= textures.size()) return m.albedo;
    const Geometry& g = geometries[h.geom];
    if (g.spheres) return m.albedo;
    const Prototype* pr =
        g.prototype >= 0 ? &prototypes[static_cast<size_t>(g.prototype)] : nullptr;
    const std::vector<glm::vec2>& uvs = pr ? pr->mesh->uvs : g.uvs;
    if (uvs.empty()) return m.albedo;
    const glm::uvec3& t = pr ? pr->mesh->triangles[h.prim] : g.triangles[h.prim];
    const glm::vec2 uv = uvs[t.x] * (1 - h.u - h.v) + uvs[t.y] * h.u + uvs[t.z] * h.v;
    // World-space edges: an instance's are its prototype's through the transform's 3 x 3 part
    // (normal_matrix up to a sign, which the cross product's length ignores).
    const std::vector<glm::vec3>& p = pr ? pr->positions : g.positions;
    glm::vec3 e1 = p[t.y] - p[t.x], e2 = p[t.z] - p[t.x];
    if (pr) e1 = g.normal_matrix * e1, e2 = g.normal_matrix * e2;
    const glm::vec3 cross = glm::cross(e1, e2);
    const float world_area = glm::length(cross);
    const glm::vec2 t1 = uvs[t.y] - uvs[t.x], t2 = uvs[t.z] - uvs[t.x];
    const float uv_area = std::fabs(t1.x * t2.y - t2.x * t1.y);
    const float cos_incidence = world_area > 0 ? std::fabs(glm::dot(cross, d)) / world_area : 1;
    const Texture& tex = *textures[m.base_color_texture];
    const float lod = texture_lod(tex, cone_width, cos_incidence, uv_area, world_area);
    return m.albedo * sample_texture(tex, uv, lod);
  }

  glm::vec3 sky_radiance(const glm::vec3& d) const {
    float y = d.y;
    glm::vec3 c = y >= 0 ? glm::mix(sky.horizon, sky.zenith, std::sqrt(y))
                         : glm::mix(sky.horizon, sky.ground, std::sqrt(-y));
    if (glm::any(glm::greaterThan(sky.sun_irradiance, glm::vec3(0))) &&
        glm::dot(d, sun_dir) > sky.sun_cos_radius) {
      c += glm::vec3(sky.sun_disc_radiance);
    }
    return c;
  }

  static float epsilon(const glm::vec3& p) {
    return 1e-4f * (1.0f + std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}));
  }

  // Direct light + ambient occlusion at a diffuse point with normal n facing the viewer.
  glm::vec3 diffuse(const glm::vec3& p, const glm::vec3& n, const glm::vec3& albedo, Rng* rng,
                    uint64_t* rays) const {
    const float eps = epsilon(p);
    const glm::vec3 o = p + n * eps;
    glm::vec3 irradiance(0);
    for (const LightAt& l : lights) {
      glm::vec3 to = l.position - p;
      float dist2 = glm::dot(to, to);
      if (!(dist2 > 0)) continue;
      float dist = std::sqrt(dist2);
      glm::vec3 dir = to / dist;
      float c = glm::dot(n, dir);
      if (c > 0 && !occluded(o, dir, dist * (1 - 1e-4f), rays)) {
        irradiance += l.intensity * (c / dist2);
      }
    }
    if (glm::any(glm::greaterThan(sky.sun_irradiance, glm::vec3(0)))) {
      float c = glm::dot(n, sun_dir);
      if (c > 0 && !occluded(o, sun_dir, INFINITY, rays)) irradiance += sky.sun_irradiance * c;
    }
    glm::vec3 color = albedo * (irradiance / kPi);
    float visible = 1;
    if (options.ao_samples > 0) {
      glm::vec3 t, b;
      basis(n, &t, &b);
      uint32_t open = 0;
      const uint64_t scramble =
          rng->net ? mix64(rng->net_key ^ (0xD1B54A32D192ED03ull * ++rng->net_calls)) : 0;
      for (uint32_t s = 0; s < options.ao_samples; ++s) {
        // Cosine-distributed direction, stratified in the first dimension (spp 1) or in both, over
        // all of the pixel's samples (spp > 1).
        float u1, u2;
        if (rng->net) {
          const SamplePoint q =
              scrambled_sequence_point(rng->net_index + s, static_cast<uint32_t>(scramble),
                                       static_cast<uint32_t>(scramble >> 32));
          u1 = q.x, u2 = q.y;
        } else {
          u1 = (static_cast<float>(s) + rng->uniform()) / static_cast<float>(options.ao_samples);
          u2 = rng->uniform();
        }
        float r = std::sqrt(u1), phi = 2 * kPi * u2;
        glm::vec3 d = t * (r * std::cos(phi)) + b * (r * std::sin(phi)) +
                      n * std::sqrt(std::max(0.0f, 1 - u1));
        if (!occluded(o, d, ao_distance, rays)) ++open;
      }
      visible = static_cast<float>(open) / static_cast<float>(options.ao_samples);
    }
    return color + albedo * ambient * visible;
  }

  // Radiance along a ray whose footprint is `cone`; `primary` receives the first hit (t = +inf on
  // a miss).
  glm::vec3 trace(const glm::vec3& o, const glm::vec3& d, const Cone& cone, uint32_t bounce,
                  Rng* rng, uint64_t* rays, Hit* primary, bool* hit_any) const {
    Hit h;
    if (!intersect(o, d, 0, INFINITY, &h, rays)) {
      if (hit_any) *hit_any = false;
      return sky_radiance(d);
    }
    if (hit_any) *hit_any = true;
    if (primary) *primary = h;
    const glm::vec3 p = o + d * h.t;
    const glm::vec3 n_out = normal(h, p);
    const bool front = glm::dot(n_out, d) < 0;
    const glm::vec3 n = front ? n_out : -n_out;  // facing the ray
    const Material& m = materials[geometries[h.geom].material];
    glm::vec3 color = m.emission;
    const float w_diffuse = std::max(0.0f, 1 - m.reflect - m.refract);
    const Cone at_hit{cone.width + cone.spread * h.t, cone.spread};
    if (w_diffuse > 0) {
      color += w_diffuse * diffuse(p, n, albedo_at(h, m, d, at_hit.width), rng, rays);
    }
    if (m.reflect > 0 || m.refract > 0) {
      const float eps = epsilon(p);
      if (bounce >= options.max_bounces) {
        color += (m.reflect + m.refract) * ambient;
      } else {
        glm::vec3 reflected = d - 2 * glm::dot(d, n) * n;
        if (m.reflect > 0) {
          color += m.reflect *
                   trace(p + n * eps, reflected, at_hit, bounce + 1, rng, rays, nullptr, nullptr);
        }
        if (m.refract > 0) {
          float eta = front ? 1 / m.ior : m.ior;
          float cosi = -glm::dot(d, n);
          float k = 1 - eta * eta * (1 - cosi * cosi);
          glm::vec3 c =
              k < 0 ? trace(p + n * eps, reflected, at_hit, bounce + 1, rng, rays, nullptr, nullptr)
                    : trace(p - n * eps, glm::normalize(eta * d + (eta * cosi - std::sqrt(k)) * n),
                            at_hit, bounce + 1, rng, rays, nullptr, nullptr);
          color += m.refract * c;
        }
      }
    }
    return color;
  }

  // The colour of a pixel as the mean of its samples (LightfieldRenderOptions: rounds doubling the
  // count until the sRGB-encoded standard error is at most `tolerance` or spp samples are taken).
  // `dir_at(x, y)` is the ray through position (x, y) in [0, 1)^2 of the pixel's square. The
  // samples themselves box-filter the pixel, so each filters textures only over its share of the
  // pixel: the footprint of the first round's stratum, `spread` (the pixel's angular width,
  // pixel_spread) / sqrt(first-round count), the same for every sample of every pixel whatever
  // count the pixel ends at. (A whole pixel's footprint per sample blurs textures twice: the box
  // of the samples over the pixel, then a mip filter as wide again.)
  template <typename DirFn>
  glm::vec3 converged_colour(const glm::vec3& o, const DirFn& dir_at, float spread, uint64_t key,
                             uint64_t* rays, uint64_t* samples) const {
    const uint64_t scramble = mix64(key ^ 0x3C6EF372FE94F82Bull);
    const uint32_t sx = static_cast<uint32_t>(scramble), sy = static_cast<uint32_t>(scramble >> 32);
    const uint32_t max_n = options.spp;
    const double tol2 = static_cast<double>(options.tolerance) * options.tolerance;
    glm::dvec3 sum(0), mean_y(0), m2_y(0);  // Welford over the sRGB-encoded samples
    uint32_t n = 0, target = std::min(std::max(options.min_spp, 1u), max_n);
    const float sample_spread = spread / std::sqrt(static_cast<float>(target));
    for (;;) {
      for (; n < target; ++n) {
        const SamplePoint p = scrambled_sequence_point(n, sx, sy);
        Rng rng(key);
        rng.net = true;
        rng.net_key = key;
        rng.net_index = n * options.ao_samples;
        const glm::vec3 c =
            trace(o, dir_at(p.x, p.y), Cone{0, sample_spread}, 0, &rng, rays, nullptr, nullptr);
        for (int i = 0; i < 3; ++i) {
          const float v = std::clamp(std::isfinite(c[i]) ? c[i] : 0.0f, 0.0f, kMaxRadiance);
          sum[i] += v;
          const double y = srgb_from_linear(v);
          const double delta = y - mean_y[i];
          mean_y[i] += delta / (n + 1);
          m2_y[i] += delta * (y - mean_y[i]);
        }
      }
      if (n >= max_n) break;
      // Standard error squared of the mean: sample variance / n. Stratified samples err less than
      // this, so the test is conservative.
      const double worst = std::max({m2_y[0], m2_y[1], m2_y[2]}) / (static_cast<double>(n - 1) * n);
      if (n > 1 && worst <= tol2) break;
      target = std::min(max_n, 2 * n);
    }
    *samples += n;
    return glm::vec3(sum / static_cast<double>(n));
  }

  // One pixel: colour (one centre sample when spp is 1, else converged_colour), and the depth and
  // material of the primary hit of the ray through the pixel centre, `centre`. `spread` is the
  // pixel's angular width (pixel_spread), which sets the texture filter's footprint.
  template <typename DirFn>
  void shade_pixel(const glm::vec3& o, const glm::vec3& centre, const DirFn& dir_at, float spread,
                   uint64_t key, uint64_t noise_key, float* rgb, float* depth, float* material,
                   uint64_t* rays, uint64_t* samples) const {
    Hit h;
    bool hit = false;
    glm::vec3 c;
    if (options.spp <= 1) {
      Rng rng(key);
      c = trace(o, centre, Cone{0, spread}, 0, &rng, rays, &h, &hit);
      ++*samples;
    } else {
      hit = intersect(o, centre, 0, INFINITY, &h, rays);
      c = converged_colour(o, dir_at, spread, key, rays, samples);
    }
    if (options.noise > 0) {
      Rng n(noise_key);
      c *= 1 + options.noise * (2 * n.uniform() - 1);
    }
    for (int i = 0; i < 3; ++i)
      rgb[i] = std::clamp(std::isfinite(c[i]) ? c[i] : 0.0f, 0.0f, kMaxRadiance);
    *depth = hit ? h.t : INFINITY;
    if (material) {
      const Material* m = hit ? &materials[geometries[h.geom].material] : nullptr;
      bool special = m && (m->reflect > 0 || m->refract > 0);
      material[0] = special ? m->reflect : 0;
      material[1] = special ? m->refract : 0;
      material[2] = special ? m->ior : 1;
    }
  }

  // Runs fn(row, &counts) for every row on the arena's threads; returns the summed counts.
  struct Counts {
    uint64_t rays = 0, samples = 0;
  };
  template <typename RowFn>
  Counts parallel_rows(uint32_t rows, const RowFn& fn) const {
    std::vector<Counts> counts(rows);
    tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                               : static_cast<int>(options.threads));
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rows),
                        [&](const tbb::blocked_range<uint32_t>& r) {
                          for (uint32_t row = r.begin(); row != r.end(); ++row) {
                            fn(row, &counts[row]);
                          }
                        });
    });
    Counts total;
    for (const Counts& c : counts) total.rays += c.rays, total.samples += c.samples;
    return total;
  }
};

Status validate_render_options(const LightfieldRenderOptions& o) {
  auto bad = [](const std::string& what) { return Status(ErrorId::kCaptureOption, what); };
  if (o.threads > 256) return bad("threads " + std::to_string(o.threads) + " is outside 0..256");
  if (o.ao_samples > 256) {
    return bad("ao-samples " + std::to_string(o.ao_samples) + " is outside 0..256");
  }
  if (o.max_bounces > 32) {
    return bad("max-bounces " + std::to_string(o.max_bounces) + " is outside 0..32");
  }
  if (!(o.noise >= 0 && o.noise <= 1)) return bad("noise must be in [0, 1]");
  if (o.spp < 1 || o.spp > 4096) return bad("spp " + std::to_string(o.spp) + " is outside 1..4096");
  if (o.min_spp < 1 || o.min_spp > 4096) {
    return bad("min-spp " + std::to_string(o.min_spp) + " is outside 1..4096");
  }
  if (!(o.tolerance >= 0 && o.tolerance <= 1)) return bad("tolerance must be in [0, 1]");
  // A pixel's AO rays are sequence points [0, spp * ao_samples): they must fit 32 bits.
  if (static_cast<uint64_t>(o.spp) * o.ao_samples > (1ull << 24)) {
    return bad("spp x ao-samples is above 2^24");
  }
  return Status::Ok();
}

FrameTracer::FrameTracer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FrameTracer::~FrameTracer() = default;

Expected<std::unique_ptr<FrameTracer>> FrameTracer::create(const Scene& scene, double time,
                                                           const LightfieldRenderOptions& options) {
  CALF_RETURN_IF_ERROR(validate_render_options(options));
  CALF_RETURN_IF_ERROR(validate_scene(scene));
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->materials = scene.materials;
  impl->textures = scene.textures;
  impl->sky = scene.sky;
  float sl = glm::length(scene.sky.sun_direction);
  impl->sun_dir = sl > 0 ? scene.sky.sun_direction / sl : glm::vec3(0, 1, 0);
  impl->ambient = scene.ambient;
  impl->ao_distance = scene.ao_distance;
  for (const PointLight& l : scene.lights) {
    impl->lights.push_back({l.position(time), l.intensity(time)});
  }
  const std::string config = options.threads ? "threads=" + std::to_string(options.threads) : "";
  impl->device = rtcNewDevice(config.c_str());
  if (!impl->device) return Status(ErrorId::kRayTracer, "Embree: cannot create a device");
  impl->rtc = new_scene(impl->device);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  auto at_time = [&](const Object& o) {
    return "object '" + o.name + "' is not finite at time " + std::to_string(time);
  };
  // Shared meshes, in order of first use (so geometry ids do not depend on pointer values).
  std::unordered_map<const TriangleMesh*, int32_t> prototype_of;
  std::vector<glm::vec3> positions;
  for (const Object& o : scene.objects) {
    if (!o.shared_mesh || prototype_of.count(o.shared_mesh.get())) continue;
    const int32_t index = static_cast<int32_t>(impl->prototypes.size());
    prototype_of.emplace(o.shared_mesh.get(), index);
    Prototype& pr = impl->prototypes.emplace_back();
    pr.mesh = o.shared_mesh;
    positions_at(*pr.mesh, time, &pr.positions);
    if (!std::all_of(pr.positions.begin(), pr.positions.end(), finite3)) {
      return Status(ErrorId::kSceneGeometry, at_time(o));
    }
    pr.scene = new_scene(impl->device);
    if (!pr.mesh->triangles.empty()) {
      CALF_RETURN_IF_ERROR(
          attach_triangles(impl->device, pr.scene, 0, pr.positions, pr.mesh->triangles));
    }
    arena.execute([&] { rtcCommitScene(pr.scene); });
  }

  for (const Object& o : scene.objects) {
    const glm::mat4 m = o.transform ? o.transform(time) : glm::mat4(1);
    const float det = glm::determinant(glm::mat3(m));
    const float scale = std::cbrt(std::fabs(det));
    if (o.shared_mesh) {
      Geometry g;
      g.material = o.material;
      g.prototype = prototype_of.at(o.shared_mesh.get());
      g.normal_matrix = glm::mat3(m) * (det < 0 ? -1.0f : 1.0f);
      for (int c = 0; c < 4; ++c) {
        if (!finite3(glm::vec3(m[c]))) return Status(ErrorId::kSceneGeometry, at_time(o));
      }
      RTCGeometry geom = rtcNewGeometry(impl->device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geom, impl->prototypes[static_cast<size_t>(g.prototype)].scene);
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &m[0][0]);
      rtcCommitGeometry(geom);
      rtcAttachGeometryByID(impl->rtc, geom, static_cast<unsigned>(impl->geometries.size()));
      rtcReleaseGeometry(geom);
      impl->geometries.push_back(std::move(g));
      continue;
    }
    for (int pass = 0; pass < 2; ++pass) {
      Geometry g;
      g.material = o.material;
      g.spheres = pass == 1;
      if (!g.spheres) {
        if (o.mesh.triangles.empty()) continue;
        g.triangles = o.mesh.triangles;
        const Material& mat = scene.materials[o.material];
        if (mat.base_color_texture != capture::kNoTexture) g.uvs = o.mesh.uvs;
        positions_at(o.mesh, time, &positions);
        g.positions.reserve(positions.size());
        for (const glm::vec3& p : positions) g.positions.emplace_back(m * glm::vec4(p, 1));
      } else {
        if (o.spheres.empty()) continue;
        for (const Sphere& sp : o.spheres) {
          g.balls.emplace_back(glm::vec3(m * glm::vec4(sp.center, 1)), sp.radius * scale);
        }
      }
      if (!std::all_of(g.positions.begin(), g.positions.end(), finite3)) {
        return Status(ErrorId::kSceneGeometry, at_time(o));
      }
      for (const glm::vec4& b : g.balls) {
        if (!finite3(glm::vec3(b)) || !(b.w > 0) || !std::isfinite(b.w)) {
          return Status(
              ErrorId::kSceneGeometry,
              "object '" + o.name + "' has a degenerate sphere at time " + std::to_string(time));
        }
      }
      const unsigned id = static_cast<unsigned>(impl->geometries.size());
      if (!g.spheres) {
        CALF_RETURN_IF_ERROR(
            attach_triangles(impl->device, impl->rtc, id, g.positions, g.triangles));
      } else {
        RTCGeometry geom = rtcNewGeometry(impl->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), g.balls.size()));
        if (!v) {
          rtcReleaseGeometry(geom);
          return Status(ErrorId::kRayTracer, "Embree: cannot allocate buffers");
        }
        for (size_t i = 0; i < g.balls.size(); ++i) {
          for (int c = 0; c < 4; ++c) v[4 * i + c] = g.balls[i][c];
        }
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(impl->rtc, geom, id);
        rtcReleaseGeometry(geom);
      }
      impl->geometries.push_back(std::move(g));
    }
  }
  arena.execute([&] { rtcCommitScene(impl->rtc); });
  if (RTCError e = rtcGetDeviceError(impl->device); e != RTC_ERROR_NONE) {
    return Status(ErrorId::kRayTracer,
                  "Embree: scene build failed with error " + std::to_string(e));
  }
  return std::unique_ptr<FrameTracer>(new FrameTracer(std::move(impl)));
}

RenderStats FrameTracer::render_cube(const Vec3& center, uint32_t view, uint32_t frame,
                                     uint32_t face_size, bool with_material,
                                     capture::ViewFrame* out, bool with_coverage) const {
  out->resize(face_size, with_material, with_coverage);
  const float coverage_tol = static_cast<float>(capture::coverage_tolerance(face_size));
  const Impl& im = *impl_;
  const glm::vec3 o = to_fvec3(center);
  const uint32_t n = face_size;
  RenderStats stats;
  const Impl::Counts counts = im.parallel_rows(6 * n, [&](uint32_t row, Impl::Counts* c) {
    const uint32_t face = row / n, y = row % n;
    const CubeFace cf = cube_face_from_index(static_cast<int>(face));
    for (uint32_t x = 0; x < n; ++x) {
      const glm::vec3 d = to_fvec3(direction_from_texel(cf, x, y, n));
      // A sample at (sx, sy) of the texel's square in face coordinates.
      auto dir_at = [&](float sx, float sy) {
        return to_fvec3(direction_from_texel_coord({cf, x + double{sx}, y + double{sy}}, n));
      };
      const size_t i = (static_cast<size_t>(face) * n + y) * n + x;
      // A face is a pinhole image 2 wide at distance 1 along its major axis.
      const float spread = pixel_spread(2.0f / static_cast<float>(n),
                                        std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}));
      // AO keys leave the frame out: static surfaces get the same samples every frame.
      im.shade_pixel(o, d, dir_at, spread, pixel_key(im.options.seed, view, face, x, y),
                     pixel_key(im.options.seed ^ 0xA5A5A5A5ull, view, face * n + y, x, frame),
                     &out->color[3 * i], &out->depth[i],
                     with_material ? &out->material[3 * i] : nullptr, &c->rays, &c->samples);
      if (with_coverage) {
        // The first hits of the centre rays of the texel's 4 x 4 cells against the centre
        // ray's depth (format/CAPTURE.md "Coverage").
        const float centre = out->depth[i];
        uint32_t near = 0, far = 0, mask = 0;
        for (uint32_t cell = 0; cell < kCoverageCells * kCoverageCells; ++cell) {
          const float cx = (static_cast<float>(cell % kCoverageCells) + 0.5f) / kCoverageCells;
          const float cy = (static_cast<float>(cell / kCoverageCells) + 0.5f) / kCoverageCells;
          Hit h;
          const bool hit = im.intersect(o, dir_at(cx, cy), 0, INFINITY, &h, &c->rays);
          const float t = hit ? h.t : INFINITY;
          if (!std::isfinite(centre)) {
            if (hit)
              ++near;
            else
              mask |= 1u << cell;
          } else if (!hit) {
            ++far;
          } else if (std::fabs(std::log(t / centre)) > coverage_tol) {
            ++(t < centre ? near : far);
          } else {
            mask |= 1u << cell;
          }
        }
        constexpr float kCells = kCoverageCells * kCoverageCells;
        out->coverage[3 * i] = static_cast<float>(near) / kCells;
        out->coverage[3 * i + 1] = static_cast<float>(far) / kCells;
        out->coverage[3 * i + 2] = static_cast<float>(mask);
      }
    }
  });
  stats.rays = counts.rays;
  stats.samples = counts.samples;
  stats.images = 1;
  stats.pixels = 6ull * n * n;
  return stats;
}

RenderStats FrameTracer::render_perspective(const capture::EyePose& pose, uint32_t width,
                                            uint32_t height, uint32_t pose_index,
                                            capture::PerspectiveImage* out) const {
  out->width = width;
  out->height = height;
  out->color.assign(static_cast<size_t>(width) * height * 3, 0.0f);
  out->depth.assign(static_cast<size_t>(width) * height, 0.0f);
  const Impl& im = *impl_;
  // The one camera model (calf/format/camera.h), as the renderers place their pixels.
  const Camera camera = capture::camera_from_pose(pose, width, height);
  const CameraFrame frame = camera_frame(camera);
  const glm::vec3 o = to_fvec3(pose.position);
  const glm::vec3 axis = to_fvec3(frame.forward);
  const float plane_pixel =
      static_cast<float>(2 * std::tan(camera.fov_y / 2) / static_cast<double>(height));
  // Sub-pixel rays: the image plane at unit distance along forward is linear in the pixel
  // position, so the point of any position follows from three of the camera model's own rays
  // (camera_ray, the one formula) without a second copy of it: the centre of pixel (0, 0) and
  // its steps to pixels (1, 0) and (0, 1).
  auto on_plane = [&](const Vec3& d) { return d * (1.0 / dot(d, frame.forward)); };
  const Vec3 p00 = on_plane(camera_ray(camera, frame, 0, 0));
  const Vec3 step_x = on_plane(camera_ray(camera, frame, 1, 0)) - p00;
  const Vec3 step_y = on_plane(camera_ray(camera, frame, 0, 1)) - p00;
  const Vec3 corner = p00 - step_x * 0.5 - step_y * 0.5;  // pixel (0, 0)'s top-left corner
  RenderStats stats;
  const Impl::Counts counts = im.parallel_rows(height, [&](uint32_t j, Impl::Counts* c) {
    for (uint32_t i = 0; i < width; ++i) {
      const glm::vec3 d = to_fvec3(camera_ray(camera, frame, i, j));
      auto dir_at = [&](float sx, float sy) {
        return to_fvec3(normalize(corner + step_x * (i + double{sx}) + step_y * (j + double{sy})));
      };
      const size_t k = static_cast<size_t>(j) * width + i;
      // Ground truth uses view id 2^32 - 1 - eye, never a capture view's.
      uint64_t view_id = 0xFFFFFFFFull - static_cast<uint64_t>(pose.eye);
      im.shade_pixel(o, d, dir_at, pixel_spread(plane_pixel, glm::dot(d, axis)),
                     pixel_key(im.options.seed, view_id, 0, i, j),
                     pixel_key(im.options.seed ^ 0xA5A5A5A5ull, view_id, j, i, pose_index),
                     &out->color[3 * k], &out->depth[k], nullptr, &c->rays, &c->samples);
    }
  });
  stats.rays = counts.rays;
  stats.samples = counts.samples;
  stats.images = 1;
  stats.pixels = static_cast<uint64_t>(width) * height;
  return stats;
}

bool FrameTracer::inside_geometry(const Vec3& point) const {
  // Winding number along each of 26 probe rays: every back-face crossing (leaving a solid) counts
  // +1, every front-face crossing (entering one) -1. For a union of closed, interpenetrating
  // solids the sum is the number of solids containing the point, whatever is embedded in what;
  // a majority vote over the rays tolerates a few open surfaces.
  const glm::vec3 o = to_fvec3(point);
  int inside_votes = 0;
  uint64_t rays = 0;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy && !dz) continue;
        const glm::vec3 d = glm::normalize(glm::vec3(dx, dy, dz));
        int winding = 0;
        float tnear = 0;
        Hit h;
        for (int crossing = 0; crossing < 256; ++crossing) {
          if (!impl_->intersect(o, d, tnear, INFINITY, &h, &rays)) break;
          if (crossing == 0 && h.t < 1e-4f) return true;  // touching a surface
          winding += glm::dot(impl_->normal(h, o + d * h.t), d) > 0 ? 1 : -1;
          tnear = h.t + 1e-5f * (1 + h.t);
        }
        if (winding > 0) ++inside_votes;
      }
    }
  }
  return inside_votes > 13;
}

bool FrameTracer::segment_clear(const Vec3& from, const Vec3& to) const {
  const glm::vec3 o = to_fvec3(from), d = to_fvec3(to) - o;
  const float length = glm::length(d);
  if (!(length > 0)) return true;
  const float stop = length - 1e-4f * (1 + length);
  if (!(stop > 0)) return true;
  uint64_t rays = 0;
  return !impl_->occluded(o, d / length, stop, &rays);
}

}  // namespace calf::samples
