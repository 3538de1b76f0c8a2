// Point merging (paper 000 Sec. 4.1): every capture sample is binned into one of six
// perspective-space voxel grids around O (cube face, face texel, log radius) and each non-empty
// voxel keeps one merged point, with the number of samples it stands for as its weight. Seurat
// keeps a reservoir-sampled representative; the mean is used here, which is deterministic without
// a random stream and, with voxels a fraction of a percent deep, never averages two surfaces.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

uint64_t morton_code(uint32_t i, uint32_t j) {
  uint64_t code = 0;
  for (uint32_t b = 0; b < kMortonLevel; ++b) {
    code |= uint64_t{(i >> b) & 1u} << (2 * b);
    code |= uint64_t{(j >> b) & 1u} << (2 * b + 1);
  }
  return code;
}

namespace {

// Face, s bin, t bin and log-radius bin packed as 3 + 20 + 20 + 21 bits.
uint64_t voxel_key(const FaceCoord& c, double radius, uint32_t grid) {
  const double g = grid;
  const uint64_t si = std::min<uint64_t>(static_cast<uint64_t>(std::max(0.0, c.s * g)), grid - 1);
  const uint64_t ti = std::min<uint64_t>(static_cast<uint64_t>(std::max(0.0, c.t * g)), grid - 1);
  // Radial bins as deep (relatively) as a texel of the grid is wide at a face's centre; radii are
  // at most 1e13 (coordinates within 1e12) and at least 1e-9, so the bin fits 21 bits for grids up
  // to 16384.
  const double bin = std::floor((std::log(std::max(radius, 1e-9)) + 21.0) * g * 0.5);
  const uint64_t ri = std::min<uint64_t>(static_cast<uint64_t>(std::max(0.0, bin)), (1u << 21) - 1);
  return (uint64_t{static_cast<uint8_t>(c.face)} << 61) | (si << 41) | (ti << 21) | ri;
}

}  // namespace

Expected<MergedPoints> merge_points(const capture::CaptureSetReader& reader, uint32_t frame,
                                    const Frame& f, const TilesBuildOptions& options) {
  const auto& manifest = reader.manifest();
  const uint32_t n = manifest.face_size;
  const uint32_t grid = options.merge_resolution ? options.merge_resolution : n;
  const size_t texels = size_t{6} * n * n;
  // Samples closer to O than this are inside the view region's core, where Seurat's energy is
  // undefined; they are dropped (geometry inside the view region is out of scope).
  const double r_min = std::max(1e-9, 0.01 * f.region_radius);

  std::unordered_map<uint64_t, uint32_t> index;
  std::vector<uint64_t> keys;
  std::vector<Vec3> sum;
  std::vector<double> count;
  capture::ViewFrame view;
  std::vector<uint64_t> view_keys(texels);
  std::vector<Vec3> view_points(texels);
  MergedPoints out;
  out.sky_roots.assign(size_t{6} << (2 * options.min_level), 0);
  for (uint32_t v = 0; v < manifest.viewpoints.size(); ++v) {
    if (options.progress) options.progress("merge", double(v) / manifest.viewpoints.size());
    CALF_RETURN_IF_ERROR(reader.read(v, frame, &view));
    const Vec3 eye = f.viewpoints[v];
    // Keys per texel in parallel (each row writes its own), inserted below in texel order.
    parallel_for(options.threads, size_t{6} * n, [&](size_t row) {
      const CubeFace face = cube_face_from_index(static_cast<int>(row / n));
      const uint32_t y = static_cast<uint32_t>(row % n);
      for (uint32_t x = 0; x < n; ++x) {
        const size_t t = view.texel_index(face, x, y);
        const float d = view.depth[t];
        view_keys[t] = ~uint64_t{0};
        if (!std::isfinite(d)) continue;
        const Vec3 q = eye + direction_from_texel(face, x, y, n) * double{d} - f.origin;
        const double r = length(q);
        if (!(r > r_min)) continue;
        view_points[t] = q;
        view_keys[t] = voxel_key(face_coord_from_direction(q), r, grid);
      }
    });
    for (size_t t = 0; t < texels; ++t) {
      if (options.sky_layer && !std::isfinite(view.depth[t])) {
        // Sky lies at infinity: its direction from the view is its direction from O.
        const CubeFace face = cube_face_from_index(static_cast<int>(t / (size_t{n} * n)));
        const uint32_t x = static_cast<uint32_t>(t % n), y = static_cast<uint32_t>((t / n) % n);
        const FaceCoord c = face_coord_from_direction(direction_from_texel(face, x, y, n));
        out.sky_roots[cell_index_at_level(c, options.min_level)] = 1;
        ++out.sky_samples;
      }
      if (view_keys[t] == ~uint64_t{0}) continue;
      ++out.samples;
      auto [it, inserted] = index.try_emplace(view_keys[t], static_cast<uint32_t>(keys.size()));
      if (inserted) {
        keys.push_back(view_keys[t]);
        sum.push_back(view_points[t]);
        count.push_back(1);
      } else {
        sum[it->second] += view_points[t];
        count[it->second] += 1;
      }
    }
  }
  if (options.progress) options.progress("merge", 1.0);
  const size_t m = keys.size();
  std::vector<Vec3> pos(m);
  std::vector<uint8_t> face(m);
  std::vector<uint64_t> code(m);
  for (size_t k = 0; k < m; ++k) {
    pos[k] = sum[k] / count[k];
    const FaceCoord c = face_coord_from_direction(pos[k]);
    const double cells = double(1u << kMortonLevel);
    const uint32_t i = std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, c.s * cells)),
                                          (1u << kMortonLevel) - 1);
    const uint32_t j = std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, c.t * cells)),
                                          (1u << kMortonLevel) - 1);
    face[k] = static_cast<uint8_t>(c.face);
    code[k] = morton_code(i, j);
    out.max_radius = std::max(out.max_radius, length(pos[k]));
  }
  // Face, then Morton order (every quadtree cell a contiguous range), the unique voxel key last.
  std::vector<uint32_t> order(m);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    if (face[a] != face[b]) return face[a] < face[b];
    if (code[a] != code[b]) return code[a] < code[b];
    return keys[a] < keys[b];
  });
  out.position.resize(m);
  out.weight.resize(m);
  out.face.resize(m);
  out.morton.resize(m);
  for (size_t k = 0; k < m; ++k) {
    out.position[k] = pos[order[k]];
    out.weight[k] = static_cast<float>(count[order[k]]);
    out.face[k] = face[order[k]];
    out.morton[k] = code[order[k]];
  }
  return out;
}

}  // namespace calf::encoder::tiles
