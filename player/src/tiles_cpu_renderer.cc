// The scalar CPU rasteriser of a tile set: the reference the GL rasteriser is tested against (what
// it does is in tiles_renderer.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "calf/format/bc.h"
#include "calf/player/tiles_renderer.h"
#include "cpu_raster.h"

namespace calf::player {
namespace {

using internal::ViewVertex;

// The atlas as floats (the halves both backends filter), and its bilinear filter with
// CLAMP_TO_EDGE: GL_LINEAR's formula on texel centres at half-integers.
class AtlasSampler {
 public:
  explicit AtlasSampler(const TilesLinearAtlas& atlas)
      : w_(atlas.width), h_(atlas.height), texels_(atlas.rgba_half.size()) {
    for (size_t k = 0; k < texels_.size(); ++k) texels_[k] = bc::half_to_float(atlas.rgba_half[k]);
  }

  std::array<float, 4> sample(double u, double v) const {
    const double x = u * w_ - 0.5, y = v * h_ - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
    const auto clamp = [](double i, uint32_t n) {
      return static_cast<size_t>(std::clamp(i, 0.0, static_cast<double>(n) - 1));
    };
    const size_t x0 = clamp(fx, w_), x1 = clamp(fx + 1, w_);
    const size_t y0 = clamp(fy, h_), y1 = clamp(fy + 1, h_);
    const float* t00 = &texels_[4 * (y0 * w_ + x0)];
    const float* t10 = &texels_[4 * (y0 * w_ + x1)];
    const float* t01 = &texels_[4 * (y1 * w_ + x0)];
    const float* t11 = &texels_[4 * (y1 * w_ + x1)];
    std::array<float, 4> out;
    for (int c = 0; c < 4; ++c) {
      const float top = t00[c] + ax * (t10[c] - t00[c]);
      const float bottom = t01[c] + ax * (t11[c] - t01[c]);
      out[c] = top + ay * (bottom - top);
    }
    return out;
  }

 private:
  size_t w_, h_;
  std::vector<float> texels_;
};

// One triangle of a tile, eye-relative.
struct TriangleTexture {
  Vec3 p[3];
  Vec3 uvw[3];
  Vec3 face;  // (p1 - p0) x (p2 - p0)
};

}  // namespace

Status render_tiles_cpu(const TileSet& set, const TilesLinearAtlas& atlas, const Camera& camera,
                        const TilesRenderOptions& options, RenderedImage* out,
                        TilesFrameStats* stats) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_tiles_render_options(options));
  CALF_RETURN_IF_ERROR(validate_tile_set(set));
  if (atlas.width != set.atlas_width || atlas.height != set.atlas_height ||
      atlas.rgba_half.size() != size_t{4} * atlas.width * atlas.height) {
    return Status(ErrorId::kTilesDraw, "the linear atlas is not the tile set's (" +
                                           std::to_string(atlas.width) + " x " +
                                           std::to_string(atlas.height) + ")");
  }
  const uint32_t width = camera.width, height = camera.height;
  const size_t pixels = size_t{width} * height;
  out->width = width;
  out->height = height;
  out->color.assign(3 * pixels, 0.0f);
  out->depth.assign(pixels, std::numeric_limits<float>::infinity());
  std::vector<uint32_t> counts(pixels, 0);
  const CameraFrame frame = camera_frame(camera);
  std::vector<Vec3> rays(pixels);
  for (uint32_t j = 0; j < height; ++j) {
    for (uint32_t i = 0; i < width; ++i)
      rays[size_t{j} * width + i] = camera_ray(camera, frame, i, j);
  }
  const internal::ViewProjector project(camera);
  const AtlasSampler sampler(atlas);
  const bool sorted = options.blend == TilesBlend::kSorted;
  std::vector<uint32_t> order;
  if (sorted) {
    tiles_back_to_front(set, camera.position, &order);
  } else {
    order.resize(set.tiles.size());
    for (size_t t = 0; t < order.size(); ++t) order[t] = static_cast<uint32_t>(t);
  }

  // kSorted's occlusion pre-pass: the nearest distance per pixel of a fragment at least
  // occlusion_alpha opaque (tiles_renderer.h); pass 0 fills it, pass 1 draws.
  const bool occlusion = sorted && options.occlusion_alpha > 0;
  std::vector<float> occluder(occlusion ? pixels : 0, std::numeric_limits<float>::infinity());
  const float occlusion_alpha = static_cast<float>(options.occlusion_alpha);
  const double behind = 1 + options.occlusion_epsilon;
  int pass = occlusion ? 0 : 1;

  TriangleTexture s;
  const auto shade = [&](uint32_t i, uint32_t j) {
    const size_t k = size_t{j} * width + i;
    if (pass == 1) ++counts[k];
    const Vec3& d = rays[k];
    const double den = dot(s.face, d);
    if (den == 0) return;
    const double dist = dot(s.face, s.p[0]) / den;
    if (!(dist > 0)) return;
    // Barycentric coordinates of the hit point: perspective-correct interpolation of (U, V, W).
    const Vec3 x = d * dist;
    const double nn = dot(s.face, s.face);
    const double l1 = dot(s.face, cross(x - s.p[0], s.p[2] - s.p[0])) / nn;
    const double l2 = dot(s.face, cross(s.p[1] - s.p[0], x - s.p[0])) / nn;
    const double l0 = 1 - l1 - l2;
    const Vec3 uvw = s.uvw[0] * l0 + s.uvw[1] * l1 + s.uvw[2] * l2;
    const std::array<float, 4> t = sampler.sample(uvw.x / uvw.z, uvw.y / uvw.z);
    const float depth = static_cast<float>(dist);
    if (pass == 0) {
      if (t[3] >= occlusion_alpha) occluder[k] = std::min(occluder[k], depth);
      return;
    }
    if (occlusion && double{depth} > double{occluder[k]} * behind) return;
    float* c = &out->color[3 * k];
    if (sorted) {
      const float keep = 1.0f - t[3];
      for (int ch = 0; ch < 3; ++ch) c[ch] = t[ch] + keep * c[ch];
      if (t[3] >= 0.5f) out->depth[k] = std::min(out->depth[k], depth);
    } else if (t[3] >= 0.5f && depth < out->depth[k]) {  // ties keep the first drawn
      for (int ch = 0; ch < 3; ++ch) c[ch] = t[ch] / t[3];
      out->depth[k] = depth;
    }
  };

  static constexpr int kTriangles[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (; pass < 2; ++pass) {
    for (uint32_t tile : order) {
      const Tile& tl = set.tiles[tile];
      for (const auto& tri : kTriangles) {
        std::array<ViewVertex, 3> view;
        for (int c = 0; c < 3; ++c) {
          const TileCorner& k = tl.corners[tri[c]];
          s.p[c] = Vec3{k.position[0], k.position[1], k.position[2]} - camera.position;
          s.uvw[c] = Vec3{k.uvw[0], k.uvw[1], k.uvw[2]};
          view[c] = {dot(s.p[c], frame.right), dot(s.p[c], frame.up), dot(s.p[c], frame.forward)};
        }
        s.face = cross(s.p[1] - s.p[0], s.p[2] - s.p[0]);
        if (!(length(s.face) > 0)) continue;  // degenerate: covers nothing
        internal::rasterise_clipped(view, options.near, project, width, height, shade);
      }
    }
  }

  if (stats != nullptr) {
    *stats = TilesFrameStats{};
    stats->measured = true;
    for (uint32_t n : counts) {
      stats->fragments += n;
      stats->covered_pixels += n > 0 ? 1 : 0;
      stats->peak = std::max(stats->peak, n);
    }
  }
  return Status::Ok();
}

}  // namespace calf::player
