// Texturing (paper 000 Sec. 5): RGBA textures for the selected tiles from the capture samples.
//
// A tile's texture covers its dilated cell in face coordinates (s, t), so texture space is the
// cube face's own (projective from O); corners sit on texel centres. Per capture view:
//   - Colour (scatter): each sample is projected from O onto the tiles of its cell; the tile whose
//     plane is nearest in relative radius (t_hit nearest 1) is its primary tile and gets the
//     sample's colour, and so do the others within solid_threshold (Seurat's crack mitigation at
//     intersecting tiles): a bilinear splat, then the least-squares fit of
//     tiles_texture_solve.cc, which undoes the renderer's bilinear magnification instead of
//     adding a second blur.
//   - Alpha (gather): each alpha supersample of each tile is looked up in the view. The view's ray
//     passes it more than solid_threshold before reaching its surface (or reaches no surface), and
//     that surface's primary tile is another tile: the view sees through the tile there. The
//     view's surface lies within solid_threshold of it and its primary tile is this tile: the
//     view sees the tile's own surface there. Seurat traces each sample's ray through the tiles;
//     gathering per supersample asks the same question and costs one depth look-up.
// Alpha from view votes (the default): a supersample's alpha is the share of the views that saw
// the tile's surface there among those that saw it or saw through it. Each view's silhouette is a
// staircase of its own pixels at its own sub-pixel offset, so the share is an anti-aliased edge
// where the hard constraints below are a jagged one.
// Alpha from constraints (Seurat's): the primary and secondary tiles of each sample get a solid
// constraint at the sample's position, seeing through gives free-space ones; supersamples holding
// both are dropped (ambiguous), every supersample takes the class of its nearest constraint (a
// two-pass chamfer transform), and a texel's alpha is the share of its supersamples that are solid.
// Texels no sample coloured are filled from their neighbours (iterated averaging, then the fit's
// membrane term; Seurat solves a Laplace equation by multigrid).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

std::array<Vec3, 4> tile_corners(const Selected& t, double dilation) {
  std::array<Vec3, 4> out;
  for (int k = 0; k < 4; ++k) {
    const Vec3 d = cell_corner_direction(t.cell, dilation, k);
    out[k] = d * plane_distance_along(t.plane, d);
  }
  return out;
}

namespace {

// The selected tiles (the sky layer's aside) grouped by cell, found from a direction through dense
// per-level tables.
class CellLookup {
 public:
  CellLookup(const Selection& sel, const TilesBuildOptions& o)
      : min_(o.min_level), max_(o.max_level) {
    for (int f = 0; f < 6; ++f) {
      for (uint32_t l = min_; l <= max_; ++l) {
        table_[f].emplace_back(size_t{1} << (2 * l), -1);
      }
    }
    for (uint32_t k = 0; k < sel.tiles.size(); ++k) {
      if (sel.tiles[k].sky) continue;  // the sky layer has its own look-up
      const CellId& c = sel.tiles[k].cell;
      int32_t& slot = table_[c.face][c.level - min_][size_t{c.j} * (1u << c.level) + c.i];
      if (slot < 0) {
        slot = static_cast<int32_t>(groups_.size());
        groups_.push_back({k, 0});
      }
      ++groups_[slot].second;
    }
  }
  // The (first tile, count) of the cell that contains face coordinate `fc`, or count 0.
  std::pair<uint32_t, uint32_t> find(const FaceCoord& fc) const {
    const int f = static_cast<int>(fc.face);
    for (uint32_t l = min_; l <= max_; ++l) {
      const uint32_t side = 1u << l;
      const uint32_t i =
          std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, fc.s * side)), side - 1);
      const uint32_t j =
          std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, fc.t * side)), side - 1);
      const int32_t slot = table_[f][l - min_][size_t{j} * side + i];
      if (slot >= 0) return groups_[slot];
    }
    return {0, 0};
  }

 private:
  uint32_t min_, max_;
  std::array<std::vector<std::vector<int32_t>>, 6> table_;
  std::vector<std::pair<uint32_t, uint32_t>> groups_;
};

// A tile's face-coordinate frame: (s, t) = (s0 + a ds, t0 + b dt) for texture position (a, b).
struct TileFrame {
  CubeFace face;
  double s0, t0, ds, dt;
};
TileFrame tile_frame(const Selected& t, double dilation) {
  double s0, t0, s1, t1;
  cell_corner_st(t.cell, dilation, 0, &s0, &t0);
  cell_corner_st(t.cell, dilation, 2, &s1, &t1);
  return {cube_face_from_index(t.cell.face), s0, t0, s1 - s0, t1 - t0};
}

struct TileWork {
  std::vector<uint8_t> marks;  // constraints: (side S)^2, bit 0 solid, bit 1 free
  std::vector<uint8_t> votes;  // view votes: (side S)^2 x (solid, free), saturating at 255
  TileNormals normals;         // colour sums (and the fit's matrix)
};

// A two-pass 3-4 chamfer transform over a g x g grid: `relax(i, from, cost)` offers cell i the
// seed reached through its neighbour `from` at that step cost. Both alpha estimates use it to give
// every supersample without a constraint or vote the value of its nearest one.
template <class Relax>
void chamfer(uint32_t g, Relax relax) {
  for (uint32_t y = 0; y < g; ++y) {
    for (uint32_t x = 0; x < g; ++x) {
      const size_t i = size_t{y} * g + x;
      if (x > 0) relax(i, i - 1, 3);
      if (y > 0) {
        relax(i, i - g, 3);
        if (x > 0) relax(i, i - g - 1, 4);
        if (x + 1 < g) relax(i, i - g + 1, 4);
      }
    }
  }
  for (uint32_t y = g; y-- > 0;) {
    for (uint32_t x = g; x-- > 0;) {
      const size_t i = size_t{y} * g + x;
      if (x + 1 < g) relax(i, i + 1, 3);
      if (y + 1 < g) {
        relax(i, i + g, 3);
        if (x + 1 < g) relax(i, i + g + 1, 4);
        if (x > 0) relax(i, i + g - 1, 4);
      }
    }
  }
}

// Alpha per supersample from Seurat's constraints: supersamples holding both kinds are dropped,
// the others take the class of the nearest constraint; 1 solid, 0 free.
std::vector<float> coverage_from_constraints(const std::vector<uint8_t>& marks, uint32_t g) {
  std::vector<uint32_t> dist(size_t{g} * g, UINT32_MAX);
  std::vector<uint8_t> label(size_t{g} * g, 0);  // 1 solid, 2 free, 0 none
  for (size_t i = 0; i < dist.size(); ++i) {
    if (marks[i] == 1 || marks[i] == 2) {
      dist[i] = 0;
      label[i] = marks[i];
    }
  }
  chamfer(g, [&](size_t i, size_t from, uint32_t cost) {
    if (dist[from] == UINT32_MAX) return;
    const uint32_t d = dist[from] + cost;
    // Ties go to solid: a crack costs more than a sliver.
    if (d < dist[i] || (d == dist[i] && label[from] == 1 && label[i] == 2)) {
      dist[i] = d;
      label[i] = label[from];
    }
  });
  std::vector<float> cover(size_t{g} * g);
  for (size_t i = 0; i < cover.size(); ++i) cover[i] = label[i] == 1 ? 1.0f : 0.0f;
  return cover;
}

// Alpha per supersample from the views' votes: the share of the views that saw the tile's surface
// there among those that saw it or saw through it; supersamples no view voted on take their
// nearest voted one's share.
std::vector<float> coverage_from_votes(const std::vector<uint8_t>& votes, uint32_t g) {
  std::vector<uint32_t> dist(size_t{g} * g, UINT32_MAX);
  std::vector<float> cover(size_t{g} * g, 0.0f);
  for (size_t i = 0; i < cover.size(); ++i) {
    const uint32_t solid = votes[2 * i], free = votes[2 * i + 1];
    if (solid + free > 0) {
      cover[i] = float(solid) / float(solid + free);
      dist[i] = 0;
    }
  }
  chamfer(g, [&](size_t i, size_t from, uint32_t cost) {
    if (dist[from] == UINT32_MAX || dist[from] + cost >= dist[i]) return;
    dist[i] = dist[from] + cost;
    cover[i] = cover[from];
  });
  return cover;
}

// options.edge_colour_weight where texel (x, y) of `face` lies on a depth edge of the view (a
// 4-neighbour on the same face more than edge_depth_ratio nearer or farther, or sky beside a
// surface), else 1.
double edge_weight(const capture::ViewFrame& view, CubeFace face, uint32_t x, uint32_t y,
                   uint32_t n, const TilesBuildOptions& options) {
  if (options.edge_colour_weight >= 1) return 1.0;
  const float d = view.depth[view.texel_index(face, x, y)];
  const double hi = 1 + options.edge_depth_ratio;
  auto differs = [&](uint32_t xx, uint32_t yy) {
    const float e = view.depth[view.texel_index(face, xx, yy)];
    if (!std::isfinite(e)) return true;
    return e > d * hi || d > e * hi;
  };
  if ((x > 0 && differs(x - 1, y)) || (x + 1 < n && differs(x + 1, y)) ||
      (y > 0 && differs(x, y - 1)) || (y + 1 < n && differs(x, y + 1))) {
    return options.edge_colour_weight;
  }
  return 1.0;
}

}  // namespace

Expected<std::vector<TileTexture>> texture_tiles(const capture::CaptureSetReader& reader,
                                                 uint32_t frame, const Frame& f,
                                                 const Selection& selection,
                                                 const std::vector<uint32_t>& sides,
                                                 const TilesBuildOptions& options) {
  const auto& manifest = reader.manifest();
  const uint32_t n = manifest.face_size;
  const uint32_t ss = options.alpha_supersampling;
  const double thresh = options.solid_threshold;
  const bool votes = options.alpha_estimate == TilesAlphaEstimate::kViewVotes;
  const size_t count = selection.tiles.size();
  CellLookup lookup(selection, options);
  std::vector<TileFrame> frames(count);
  std::vector<TileWork> work(count);
  for (size_t k = 0; k < count; ++k) {
    frames[k] = tile_frame(selection.tiles[k], options.tile_dilation);
    const size_t supersamples = size_t{sides[k]} * ss * sides[k] * ss;
    if (votes) {
      work[k].votes.assign(2 * supersamples, 0);
    } else {
      work[k].marks.assign(supersamples, 0);
    }
    work[k].normals.reset(sides[k], options.texture_solve_iterations > 0);
  }

  // The sky layer's tiles by root cell (face, j, i); empty without any.
  std::vector<int32_t> sky_of_root;
  for (size_t k = 0; k < count; ++k) {
    const Selected& tile = selection.tiles[k];
    if (!tile.sky) continue;
    const uint32_t root = 1u << options.min_level;
    if (sky_of_root.empty()) sky_of_root.assign(size_t{6} * root * root, -1);
    sky_of_root[(size_t{tile.cell.face} * root + tile.cell.j) * root + tile.cell.i] =
        static_cast<int32_t>(k);
  }

  const size_t texels = size_t{6} * n * n;
  std::vector<int32_t> primary(texels);
  std::vector<float> sample_a(texels), sample_b(texels);
  capture::ViewFrame view;
  for (uint32_t v = 0; v < manifest.viewpoints.size(); ++v) {
    if (options.progress) options.progress("texture", double(v) / manifest.viewpoints.size());
    CALF_RETURN_IF_ERROR(reader.read(v, frame, &view));
    const Vec3 eye = f.viewpoints[v];
    // Each sample's primary tile and texture position (per row in parallel).
    parallel_for(options.threads, size_t{6} * n, [&](size_t row) {
      const CubeFace face = cube_face_from_index(static_cast<int>(row / n));
      const uint32_t y = static_cast<uint32_t>(row % n);
      for (uint32_t x = 0; x < n; ++x) {
        const size_t t = view.texel_index(face, x, y);
        primary[t] = -1;
        const float depth = view.depth[t];
        if (!std::isfinite(depth)) continue;
        const Vec3 q = eye + direction_from_texel(face, x, y, n) * double{depth} - f.origin;
        const double r = length(q);
        if (!(r > 0)) continue;
        const Vec3 d = q / r;
        const FaceCoord fc = face_coord_from_direction(d);
        const auto [first, cnt] = lookup.find(fc);
        double best = 1e300;
        for (uint32_t k = first; k < first + cnt; ++k) {
          const double dist = plane_distance_along(selection.tiles[k].plane, d);
          if (!(dist > 0)) continue;
          const double err = std::abs(dist / r - 1.0);
          if (err < best) {
            best = err;
            primary[t] = static_cast<int32_t>(k);
          }
        }
        if (primary[t] >= 0) {
          const TileFrame& tf = frames[primary[t]];
          sample_a[t] = static_cast<float>((fc.s - tf.s0) / tf.ds);
          sample_b[t] = static_cast<float>((fc.t - tf.t0) / tf.dt);
        }
      }
    });
    // Solid constraints and colour, accumulated in texel order (the sums do not depend on the
    // thread count).
    for (size_t t = 0; t < texels; ++t) {
      const int32_t p = primary[t];
      const CubeFace face = cube_face_from_index(static_cast<int>(t / (size_t{n} * n)));
      const uint32_t x = static_cast<uint32_t>(t % n), y = static_cast<uint32_t>((t / n) % n);
      if (p < 0 && !sky_of_root.empty() && !std::isfinite(view.depth[t])) {
        // Sky: at infinity, its direction from the view is its direction from O.
        const FaceCoord fc = face_coord_from_direction(direction_from_texel(face, x, y, n));
        const int32_t k = sky_of_root[cell_index_at_level(fc, options.min_level)];
        if (k < 0) continue;
        const TileFrame& tf = frames[k];
        const double side1 = sides[k] - 1.0;
        work[k].normals.add((fc.s - tf.s0) / tf.ds * side1, (fc.t - tf.t0) / tf.dt * side1,
                            &view.color[3 * t]);
        continue;
      }
      if (p < 0) continue;
      const double depth = view.depth[t];
      const double edge = edge_weight(view, face, x, y, n, options);
      const Vec3 q = eye + direction_from_texel(face, x, y, n) * depth - f.origin;
      const double r = length(q);
      const Vec3 d = q / r;
      const auto [first, cnt] = lookup.find(face_coord_from_direction(d));
      for (uint32_t k = first; k < first + cnt; ++k) {
        double weight = 1.0;
        if (static_cast<int32_t>(k) != p) {
          const double dist = plane_distance_along(selection.tiles[k].plane, d);
          if (!(dist > 0) || std::abs(dist / r - 1.0) >= thresh) continue;
          weight = options.secondary_colour_weight;
        }
        const uint32_t side = sides[k];
        const double u = sample_a[t] * (side - 1.0), w = sample_b[t] * (side - 1.0);
        const uint32_t g = side * ss;
        const int sx = std::clamp(static_cast<int>(std::floor((u + 0.5) * ss)), 0, int(g) - 1);
        const int sy = std::clamp(static_cast<int>(std::floor((w + 0.5) * ss)), 0, int(g) - 1);
        if (!votes) work[k].marks[size_t(sy) * g + sx] |= 1;
        weight *= edge;
        if (weight > 0) work[k].normals.add(u, w, &view.color[3 * t], weight);
      }
    }
    // Free space: each tile's supersamples against this view (per tile in parallel).
    parallel_for(options.threads, count, [&](size_t k) {
      const Selected& tile = selection.tiles[k];
      if (tile.sky) return;  // opaque: nothing is seen through the sky
      const TileFrame& tf = frames[k];
      const uint32_t side = sides[k], g = side * ss;
      for (uint32_t sy = 0; sy < g; ++sy) {
        for (uint32_t sx = 0; sx < g; ++sx) {
          const double a = ((sx + 0.5) / ss - 0.5) / (side - 1.0);
          const double b = ((sy + 0.5) / ss - 0.5) / (side - 1.0);
          FaceCoord fc;
          fc.face = tf.face;
          fc.s = tf.s0 + a * tf.ds;
          fc.t = tf.t0 + b * tf.dt;
          const Vec3 d = direction_from_face_coord(fc);
          const double dist = plane_distance_along(tile.plane, d);
          if (!(dist > 0)) continue;
          const Vec3 ray = f.origin + d * dist - eye;
          const double len = length(ray);
          if (!(len > 0)) continue;
          const Texel tx = texel_from_direction(ray, n);
          const size_t t = view.texel_index(tx.face, tx.x, tx.y);
          const float depth = view.depth[t];
          const bool through =
              !std::isfinite(depth) || (len < depth * (1.0 - thresh) && primary[t] != int32_t(k));
          if (!votes) {
            if (through) work[k].marks[size_t{sy} * g + sx] |= 2;
            continue;
          }
          // The view saw this tile's own surface here (its sample's primary tile is this one).
          const bool on = std::isfinite(depth) && std::abs(len - depth) <= thresh * depth &&
                          primary[t] == int32_t(k);
          uint8_t* vote = &work[k].votes[2 * (size_t{sy} * g + sx)];
          if (on && vote[0] < 255) ++vote[0];
          if (through && vote[1] < 255) ++vote[1];
        }
      }
    });
  }
  if (options.progress) options.progress("texture", 1.0);

  // Resolve alpha and colour per tile.
  std::vector<TileTexture> out(count);
  parallel_for(options.threads, count, [&](size_t k) {
    const uint32_t side = sides[k], g = side * ss;
    TileWork& w = work[k];
    const std::vector<float> cover =
        votes ? coverage_from_votes(w.votes, g) : coverage_from_constraints(w.marks, g);
    TileTexture& tex = out[k];
    tex.side = side;
    tex.rgba.assign(size_t{side} * side * 4, 0.0f);
    std::vector<uint8_t> known(size_t{side} * side, 0);
    for (uint32_t y = 0; y < side; ++y) {
      for (uint32_t x = 0; x < side; ++x) {
        float solid = 0;
        for (uint32_t qy = 0; qy < ss; ++qy) {
          for (uint32_t qx = 0; qx < ss; ++qx)
            solid += cover[size_t{y * ss + qy} * g + x * ss + qx];
        }
        const size_t i = size_t{y} * side + x;
        tex.rgba[4 * i + 3] = selection.tiles[k].sky ? 1.0f : solid / float(ss * ss);
        const float wsum = w.normals.sums[4 * i + 3];
        if (wsum > 0) {
          for (int c = 0; c < 3; ++c) tex.rgba[4 * i + c] = w.normals.sums[4 * i + c] / wsum;
          known[i] = 1;
        }
      }
    }
    // Fill uncoloured texels from coloured neighbours, one ring per pass.
    for (uint32_t pass = 0; pass < 2 * side; ++pass) {
      std::vector<uint8_t> next = known;
      bool changed = false;
      for (uint32_t y = 0; y < side; ++y) {
        for (uint32_t x = 0; x < side; ++x) {
          const size_t i = size_t{y} * side + x;
          if (known[i]) continue;
          float sum[3] = {0, 0, 0};
          int cnt = 0;
          const int nx[4] = {int(x) - 1, int(x) + 1, int(x), int(x)};
          const int ny[4] = {int(y), int(y), int(y) - 1, int(y) + 1};
          for (int q = 0; q < 4; ++q) {
            if (nx[q] < 0 || ny[q] < 0 || nx[q] >= int(side) || ny[q] >= int(side)) continue;
            const size_t j = size_t(ny[q]) * side + nx[q];
            if (!known[j]) continue;
            for (int c = 0; c < 3; ++c) sum[c] += tex.rgba[4 * j + c];
            ++cnt;
          }
          if (cnt == 0) continue;
          for (int c = 0; c < 3; ++c) tex.rgba[4 * i + c] = sum[c] / cnt;
          next[i] = 1;
          changed = true;
        }
      }
      known.swap(next);
      if (!changed) break;
    }
    solve_tile_colour(w.normals, options.texture_smoothness, options.texture_solve_iterations,
                      tex.rgba.data());
    w = TileWork{};  // free the work buffers early
  });
  return out;
}

}  // namespace calf::encoder::tiles
