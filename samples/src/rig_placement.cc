// Camera placement, paper 002 Sec. 4 Alg. 1 (rig_placement.h): the coverage model of Eqs. 2-7
// evaluated on area-uniform surface points, and the greedy selection over a candidate grid.
#include "calf/samples/rig_placement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/samples/render.h"
#include "glm_vec.h"
#include "surface_points.h"

namespace calf::samples {

const char* const kPlacementSyntaxHelp =
    "auto[:KEY=VALUE]...               paper 002 Alg. 1: greedy coverage placement in the view\n"
    "                                  volume; keys (defaults): max=16 (most cameras, 1..256),\n"
    "                                  stop=0.01 (stop when a camera's gain is below this share\n"
    "                                  of the best reachable coverage), k=1 (proximity decay per\n"
    "                                  scene length: 1 unit for built-in scenes, a model file's\n"
    "                                  bounding radius), candidates=512, samples=16384 (surface "
    "points),\n"
    "                                  frames=1 (frames of Eq. 7), specular (Eq. 6), theta=50\n"
    "                                  (degrees; implies specular), seed=1,\n"
    "                                  volume=X0,Y0,Z0,X1,Y1,Z1 (default: the scene's own)\n"
    "hammersley:N[:KEY=VALUE]...       N views at 3D Hammersley points of the same volume "
    "(Seurat);\n"
    "                                  the keys above set the coverage report";

namespace {

// One line whatever the text holds: control characters are written as \xNN.
Status placement_error(std::string_view text, const std::string& why) {
  const std::string raw =
      "--rig '" + std::string(text) + "': " + why + " (see --help for auto/hammersley)";
  std::string line;
  for (char c : raw) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      line += buf;
    } else {
      line += c;
    }
  }
  return Status(ErrorId::kPlacementSyntax, line);
}

bool parse_double(std::string_view s, double* v) {
  std::string item(s);
  if (item.empty()) return false;
  char* end = nullptr;
  *v = std::strtod(item.c_str(), &end);
  return end == item.c_str() + item.size() && std::isfinite(*v);
}

bool parse_count(std::string_view s, uint32_t lo, uint32_t hi, uint32_t* out) {
  double v = 0;
  if (!parse_double(s, &v) || v < lo || v > hi || v != std::floor(v)) return false;
  *out = static_cast<uint32_t>(v);
  return true;
}

double radical_inverse(uint32_t i, uint32_t base) {
  double inv = 1.0 / base, f = inv, r = 0;
  while (i > 0) {
    r += f * (i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

double distance_to_box(const glm::dvec3& p, const Box3& b) {
  const glm::dvec3 lo = to_dvec3(b.min), hi = to_dvec3(b.max);
  return glm::length(glm::max(glm::max(lo - p, p - hi), glm::dvec3(0)));
}

// Where viewers may be: the view volume less the rig's keep-out ball.
struct ViewerRegion {
  Box3 box;
  glm::dvec3 keep_out_center{0};
  double keep_out_radius = 0;

  bool kept_out(const glm::dvec3& p) const {
    return glm::length(p - keep_out_center) < keep_out_radius;
  }
  // Z(x), the minimum viewer distance: no viewer is nearer to x than the box, nor (from inside
  // the ball) than the ball's surface. A lower bound where the ball pokes out of the box.
  double min_viewer_distance(const glm::dvec3& x) const {
    return std::max(distance_to_box(x, box), keep_out_radius - glm::length(x - keep_out_center));
  }
};

// About `n` points on a regular grid spanning `volume`, ends included (so that its corners,
// where hand-made rigs put cameras, are candidates too); an axis of zero extent gets one point.
std::vector<Vec3> candidate_grid(const Box3& volume, uint32_t n) {
  const glm::dvec3 lo = to_dvec3(volume.min), hi = to_dvec3(volume.max), e = hi - lo;
  double measure = 1;
  int dims = 0;
  for (int a = 0; a < 3; ++a) {
    if (e[a] > 0) measure *= e[a], ++dims;
  }
  glm::uvec3 count(1);
  if (dims > 0) {
    const double cell = std::pow(measure / n, 1.0 / dims);
    for (int a = 0; a < 3; ++a) {
      if (e[a] > 0)
        count[a] = static_cast<uint32_t>(std::clamp(std::lround(e[a] / cell), 1l, 4096l));
    }
    if (n > 1 && count.x * count.y * count.z == 1) {
      // A volume whose longest side is below one cell: put the points along it.
      int a = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
      count[a] = std::min(n, 4096u);
    }
  }
  auto at = [](uint32_t i, uint32_t c, double a, double b) {
    return c == 1 ? (a + b) / 2 : a + (b - a) * i / (c - 1);
  };
  std::vector<Vec3> points;
  for (uint32_t z = 0; z < count.z; ++z) {
    for (uint32_t y = 0; y < count.y; ++y) {
      for (uint32_t x = 0; x < count.x; ++x) {
        points.push_back(
            {at(x, count.x, lo.x, hi.x), at(y, count.y, lo.y, hi.y), at(z, count.z, lo.z, hi.z)});
      }
    }
  }
  return points;
}

// The suitability of every evaluated point for every surface sample (Eq. 2), and the samples.
struct CoverageField {
  std::vector<glm::dvec3> points;  // evaluated viewpoints
  std::vector<glm::vec3> samples;  // surface points of all frames
  std::vector<double> weights;     // per sample: its frame's area / samples / frames
  std::vector<float> suit;         // points.size() x samples.size(), point-major
  double reference = 0;            // R: integral of max over points of I_suit
  const float* row(size_t p) const { return &suit[p * samples.size()]; }
};

// Gain of point `c` against the coverage so far (Eqs. 3-4, or 6 when specular). `best` holds,
// in the diffuse variant, max over chosen cameras of I_suit per sample; `chosen` the chosen point
// indices for the specular variant.
double gain_of(const CoverageField& f, size_t c, const std::vector<float>& best,
               const std::vector<size_t>& chosen, bool specular, double cos_theta) {
  const float* r = f.row(c);
  double g = 0;
  const size_t n = f.samples.size();
  for (size_t s = 0; s < n; ++s) {
    if (r[s] <= 0) continue;
    float covered = 0;
    if (!specular) {
      covered = best[s];
    } else {
      const glm::dvec3 x(f.samples[s]);
      const glm::dvec3 to_c = glm::normalize(f.points[c] - x);
      for (size_t j : chosen) {
        const float v = f.row(j)[s];
        if (v <= covered) continue;
        // Within theta of O's direction: that camera already sees x from (about) here.
        if (glm::dot(to_c, glm::normalize(f.points[j] - x)) >= cos_theta) covered = v;
      }
    }
    if (r[s] > covered) g += f.weights[s] * static_cast<double>(r[s] - covered);
  }
  return g;
}

// Cameras added in order: the gain of each over R and the running coverage.
struct Accumulator {
  const CoverageField* f;
  bool specular;
  double cos_theta;
  std::vector<float> best;
  std::vector<size_t> chosen;
  double total = 0;

  Accumulator(const CoverageField& field, bool spec, double cos_t)
      : f(&field), specular(spec), cos_theta(cos_t), best(field.samples.size(), 0.0f) {}
  double gain(size_t c) const { return gain_of(*f, c, best, chosen, specular, cos_theta); }
  // Adds point c; returns its gain over R.
  double add(size_t c) {
    const double g = gain(c) / f->reference;
    const float* r = f->row(c);
    for (size_t s = 0; s < best.size(); ++s) best[s] = std::max(best[s], r[s]);
    chosen.push_back(c);
    total += g;
    return g;
  }
};

}  // namespace

bool is_placement_rig(std::string_view text) {
  return text == "auto" || text.starts_with("auto:") || text.starts_with("hammersley:") ||
         text == "hammersley";
}

Expected<PlacementOptions> parse_placement(std::string_view text) {
  PlacementOptions o;
  o.text = std::string(text);
  std::vector<std::string_view> items;
  size_t at = 0;
  while (true) {
    size_t colon = text.find(':', at);
    items.push_back(text.substr(at, colon == text.npos ? text.npos : colon - at));
    if (colon == text.npos) break;
    at = colon + 1;
  }
  size_t first = 1;
  if (items[0] == "auto") {
    o.kind = PlacementOptions::Kind::kAuto;
  } else if (items[0] == "hammersley") {
    o.kind = PlacementOptions::Kind::kHammersley;
    if (items.size() < 2 || !parse_count(items[1], 1, 256, &o.max_cameras)) {
      return placement_error(text, "hammersley takes a count N in 1..256 first");
    }
    o.stop = 0;
    first = 2;
  } else {
    return placement_error(text, "not an auto or hammersley rig");
  }
  for (size_t i = first; i < items.size(); ++i) {
    const std::string_view item = items[i];
    const size_t eq = item.find('=');
    const std::string_view key = item.substr(0, eq);
    const std::string_view value = eq == item.npos ? std::string_view() : item.substr(eq + 1);
    double v = 0;
    auto bad = [&](const char* range) {
      std::string why = "'";
      why.append(item).append("': ").append(range);
      return placement_error(text, why);
    };
    if (key == "specular" && eq == item.npos) {
      o.specular = true;
    } else if (eq == item.npos) {
      return placement_error(text, std::string("'").append(item).append("' is not KEY=VALUE"));
    } else if (key == "max") {
      if (o.kind == PlacementOptions::Kind::kHammersley) return bad("hammersley's count is N");
      if (!parse_count(value, 1, 256, &o.max_cameras)) return bad("max is an integer in 1..256");
    } else if (key == "candidates") {
      if (!parse_count(value, 1, 65536, &o.candidates)) return bad("an integer in 1..65536");
    } else if (key == "samples") {
      if (!parse_count(value, 16, 4194304, &o.samples)) return bad("an integer in 16..4194304");
    } else if (key == "frames") {
      if (!parse_count(value, 1, 256, &o.frames)) return bad("an integer in 1..256");
    } else if (key == "seed") {
      if (!parse_double(value, &v) || v < 0 || v > 9007199254740992.0 || v != std::floor(v)) {
        return bad("a non-negative integer");
      }
      o.seed = static_cast<uint64_t>(v);
    } else if (key == "k") {
      if (!parse_double(value, &o.k) || o.k < 0 || o.k > 1e6) return bad("a number in [0, 1e6]");
    } else if (key == "stop") {
      if (!parse_double(value, &o.stop) || o.stop < 0 || o.stop > 1) return bad("in [0, 1]");
    } else if (key == "theta") {
      if (!parse_double(value, &o.theta_degrees) || !(o.theta_degrees > 0) ||
          o.theta_degrees > 180) {
        return bad("degrees in (0, 180]");
      }
      o.specular = true;
    } else if (key == "volume") {
      double b[6];
      size_t pos = 0;
      int n = 0;
      bool last = false;
      while (n < 6 && !last) {
        const size_t comma = value.find(',', pos);
        if (!parse_double(value.substr(pos, comma == value.npos ? value.npos : comma - pos),
                          &b[n])) {
          return bad("six numbers X0,Y0,Z0,X1,Y1,Z1");
        }
        ++n;
        last = comma == value.npos;
        pos = comma + 1;
      }
      if (n != 6 || !last || std::fabs(b[0]) > 1e12 || std::fabs(b[1]) > 1e12 ||
          std::fabs(b[2]) > 1e12 || std::fabs(b[3]) > 1e12 || std::fabs(b[4]) > 1e12 ||
          std::fabs(b[5]) > 1e12) {
        return bad("six numbers X0,Y0,Z0,X1,Y1,Z1 within +-1e12");
      }
      if (b[0] > b[3] || b[1] > b[4] || b[2] > b[5]) return bad("X0 <= X1, Y0 <= Y1, Z0 <= Z1");
      o.has_volume = true;
      o.volume = {{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
    } else {
      return placement_error(text, "unknown key '" + std::string(key) + "'");
    }
  }
  return o;
}

Vec3 hammersley_point(uint32_t i, uint32_t n, const Box3& v) {
  const double u[3] = {static_cast<double>(i) / n, radical_inverse(i, 2), radical_inverse(i, 3)};
  return {v.min.x + (v.max.x - v.min.x) * u[0], v.min.y + (v.max.y - v.min.y) * u[1],
          v.min.z + (v.max.z - v.min.z) * u[2]};
}

Expected<PlacementResult> place_cameras(const Scene& scene, const PlacementOptions& options,
                                        uint32_t capture_frames) {
  const auto start = std::chrono::steady_clock::now();
  const Box3 volume = options.has_volume ? options.volume : scene.default_rig.view_volume;
  const ViewerRegion region{volume, to_dvec3(scene.default_rig.keep_out_center),
                            scene.default_rig.keep_out_radius};
  // k is per the scene's length scale, so a model's rig does not depend on its file's unit.
  const double k = options.k / scene.length_scale;
  const uint32_t frames = std::max(1u, capture_frames);
  LightfieldRenderOptions render;
  render.threads = options.threads;
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));

  // Evaluated points: the candidate grid, then Hammersley sets of 1..M points (M: the curve's
  // length), then the scene's own rig. Points inside geometry at any frame are dropped; the
  // Hammersley set of n grows until n of its points are outside.
  const std::vector<Vec3> grid = candidate_grid(volume, options.candidates);
  const uint32_t m = options.max_cameras;
  const std::vector<capture::Viewpoint>& hand = scene.default_rig.viewpoints;
  std::vector<uint32_t> eq7_frames;
  for (uint32_t i = 0; i < std::min(options.frames, frames); ++i) {
    eq7_frames.push_back(static_cast<uint32_t>(static_cast<uint64_t>(i) * frames /
                                               std::min(options.frames, frames)));
  }
  // Every point that may be evaluated: the grid, then for each n the Hammersley sets of n to
  // 2n points (the first with n points outside geometry is used). One pass over all
  // capture frames flags those inside geometry at any of them; the Eq. 7 frames stay built.
  constexpr uint32_t kGrow = 4;  // sizes n + j ceil(n / 4), j = 0..kGrow: up to twice n
  auto grown = [](uint32_t n, uint32_t j) { return n + j * ((n + 3) / 4); };
  std::vector<Vec3> probe = grid;
  std::vector<std::vector<size_t>> sets;  // probe indices of the Hammersley set of size (n, extra)
  for (uint32_t n = 1; n <= m; ++n) {
    for (uint32_t j = 0; j <= kGrow; ++j) {
      const uint32_t size = grown(n, j);
      sets.emplace_back();
      for (uint32_t i = 0; i < size; ++i) {
        sets.back().push_back(probe.size());
        probe.push_back(hammersley_point(i, size, volume));
      }
    }
  }
  // Outside geometry (and outside the keep-out ball: no viewer there either).
  std::vector<char> outside(probe.size(), 1);
  for (size_t i = 0; i < probe.size(); ++i) {
    if (region.kept_out(to_dvec3(probe[i]))) outside[i] = 0;
  }
  std::vector<std::unique_ptr<FrameTracer>> tracers(eq7_frames.size());
  for (uint32_t f = 0; f < frames; ++f) {
    CALF_ASSIGN_OR_RETURN(std::unique_ptr<FrameTracer> t,
                          FrameTracer::create(scene, f / scene.fps, render));
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, probe.size(), [&](size_t i) {
        if (outside[i] && t->inside_geometry(probe[i])) outside[i] = 0;
      });
    });
    auto it = std::find(eq7_frames.begin(), eq7_frames.end(), f);
    if (it != eq7_frames.end())
      tracers[static_cast<size_t>(it - eq7_frames.begin())] = std::move(t);
  }

  CoverageField field;
  std::vector<size_t> candidates;  // indices into field.points
  for (size_t i = 0; i < grid.size(); ++i) {
    if (outside[i])
      candidates.push_back(field.points.size()), field.points.push_back(to_dvec3(grid[i]));
  }
  if (candidates.empty()) {
    return Status(ErrorId::kPlacementVolume,
                  "--rig '" + options.text + "': all " + std::to_string(grid.size()) +
                      " candidate points of the view volume lie inside geometry" +
                      (region.keep_out_radius > 0 ? " or the rig's keep-out ball" : ""));
  }
  // hammersley[n - 1]: the point indices of the n-point set.
  std::vector<std::vector<size_t>> hammersley(m);
  for (uint32_t n = 1; n <= m; ++n) {
    for (uint32_t extra = 0; extra <= kGrow && hammersley[n - 1].empty(); ++extra) {
      const std::vector<size_t>& set = sets[(n - 1) * (kGrow + 1) + extra];
      std::vector<size_t> kept;
      for (size_t i : set) {
        if (outside[i] && kept.size() < n) kept.push_back(i);
      }
      if (kept.size() < n) continue;
      for (size_t i : kept) {
        hammersley[n - 1].push_back(field.points.size());
        field.points.push_back(to_dvec3(probe[i]));
      }
    }
    if (hammersley[n - 1].empty()) {
      return Status(ErrorId::kPlacementVolume,
                    "--rig '" + options.text + "': fewer than " + std::to_string(n) + " of " +
                        std::to_string(grown(n, kGrow)) +
                        " Hammersley points of the view volume lie outside geometry" +
                        (region.keep_out_radius > 0 ? " and the rig's keep-out ball" : ""));
    }
  }
  std::vector<size_t> hand_points;
  for (const capture::Viewpoint& v : hand) {
    hand_points.push_back(field.points.size());
    field.points.push_back(to_dvec3(v.position));
  }

  // Surface samples of the Eq. 7 frames, then suitability (Eq. 2) of every point for each.
  const uint32_t per_frame =
      std::max(1u, options.samples / static_cast<uint32_t>(eq7_frames.size()));
  std::vector<size_t> frame_begin;
  for (size_t i = 0; i < eq7_frames.size(); ++i) {
    SurfacePoints sp =
        sample_surface_points(scene, eq7_frames[i] / scene.fps, per_frame, options.seed + i);
    frame_begin.push_back(field.samples.size());
    const double w = sp.positions.empty() ? 0 : sp.area / sp.positions.size() / eq7_frames.size();
    for (const glm::vec3& p : sp.positions) field.samples.push_back(p), field.weights.push_back(w);
  }
  frame_begin.push_back(field.samples.size());
  const size_t ns = field.samples.size(), np = field.points.size();
  std::vector<double> z(ns);
  for (size_t s = 0; s < ns; ++s) z[s] = region.min_viewer_distance(glm::dvec3(field.samples[s]));
  field.suit.assign(np * ns, 0.0f);
  for (size_t i = 0; i < eq7_frames.size(); ++i) {
    const FrameTracer* t = tracers[i].get();
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, np, [&](size_t p) {
        float* row = &field.suit[p * ns];
        const Vec3 o = to_vec3(field.points[p]);
        for (size_t s = frame_begin[i]; s < frame_begin[i + 1]; ++s) {
          const glm::dvec3 x(field.samples[s]);
          if (!t->segment_clear(o, to_vec3(x))) continue;
          const double excess = std::max(glm::length(x - field.points[p]) - z[s], 0.0);
          row[s] = static_cast<float>(std::exp(-k * excess));
        }
      });
    });
  }
  for (size_t s = 0; s < ns; ++s) {
    float best = 0;
    for (size_t p = 0; p < np; ++p) best = std::max(best, field.suit[p * ns + s]);
    field.reference += field.weights[s] * best;
  }
  if (!(field.reference > 0)) {
    return Status(ErrorId::kPlacementVolume,
                  "--rig '" + options.text + "': no point of the view volume sees any surface");
  }

  // Alg. 1.
  const bool spec = options.specular;
  const double cos_theta = std::cos(options.theta_degrees * M_PI / 180);
  PlacementResult result;
  result.candidates = static_cast<uint32_t>(candidates.size());
  result.length_scale = scene.length_scale;
  result.surface_samples = static_cast<uint32_t>(ns);
  result.rays = static_cast<uint64_t>(np) * ns;
  Accumulator greedy(field, spec, cos_theta);
  std::vector<double> gains(candidates.size());
  result.stop_reason = "reached max=" + std::to_string(m);
  for (uint32_t n = 1; n <= m; ++n) {
    arena.execute([&] {
      tbb::parallel_for(size_t{0}, candidates.size(),
                        [&](size_t i) { gains[i] = greedy.gain(candidates[i]); });
    });
    size_t pick = 0;
    for (size_t i = 1; i < gains.size(); ++i) {
      if (gains[i] > gains[pick]) pick = i;
    }
    const double share = gains[pick] / field.reference;
    if (!(gains[pick] > 0)) {
      result.stop_reason = "no candidate gains anything (the paper's y > 0)";
      break;
    }
    if (share < options.stop) {
      result.stop_reason = "the next gain " + std::to_string(share) +
                           " < stop=" + std::to_string(options.stop) + " of the reachable coverage";
      break;
    }
    CoverageRow row;
    row.cameras = n;
    row.position = to_vec3(field.points[candidates[pick]]);
    row.gain = greedy.add(candidates[pick]);
    row.coverage = greedy.total;
    result.curve.push_back(row);
  }
  // The comparisons at equal counts.
  auto coverage_of = [&](const std::vector<size_t>& pts, size_t count) {
    Accumulator a(field, spec, cos_theta);
    for (size_t i = 0; i < count && i < pts.size(); ++i) a.add(pts[i]);
    return a.total;
  };
  for (CoverageRow& row : result.curve) {
    row.hammersley = coverage_of(hammersley[row.cameras - 1], row.cameras);
    if (row.cameras <= hand_points.size()) row.hand_made = coverage_of(hand_points, row.cameras);
  }
  result.hand_made_count = static_cast<uint32_t>(hand_points.size());
  result.hand_made_coverage = coverage_of(hand_points, hand_points.size());

  Rig& rig = result.rig;
  rig.view_volume = volume;
  rig.keep_out_center = to_vec3(region.keep_out_center);
  rig.keep_out_radius = region.keep_out_radius;
  rig.description = options.text;
  if (options.kind == PlacementOptions::Kind::kAuto) {
    for (const CoverageRow& row : result.curve) {
      rig.viewpoints.push_back({"auto" + std::to_string(row.cameras - 1), row.position});
    }
    result.hammersley_coverage = result.curve.empty() ? 0 : result.curve.back().hammersley;
  } else {
    const std::vector<size_t>& set = hammersley[m - 1];
    for (size_t i = 0; i < set.size(); ++i) {
      rig.viewpoints.push_back({"hammersley" + std::to_string(i), to_vec3(field.points[set[i]])});
    }
    result.hammersley_coverage = coverage_of(set, set.size());
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace calf::samples
