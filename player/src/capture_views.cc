#include "calf/player/capture_views.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calf/format/log_depth.h"
#include "sampling.h"

namespace calf::player {

namespace {

Status views_error(std::string_view context, const std::string& what) {
  return Status(ErrorId::kPlayerCaptureViews,
                context.empty() ? what : std::string(context) + ": " + what);
}

}  // namespace

Expected<View> view_from_capture_frame(const capture::ViewFrame& frame, const Vec3& position,
                                       std::string_view context) {
  const uint32_t n = frame.face_size;
  const size_t texels = frame.texel_count();
  if (n == 0 || frame.color.size() != 3 * texels || frame.depth.size() != texels ||
      frame.material.size() != (frame.has_material ? 3 * texels : 0) ||
      frame.coverage.size() != (frame.has_coverage ? 3 * texels : 0)) {
    return views_error(context, "view-frame buffers do not match face size " + std::to_string(n));
  }
  // The range covers exactly this view-frame's finite depths; invalid depths are rejected here
  // rather than silently coded (the reader validates too, but a frame may come from elsewhere).
  float lo = INFINITY, hi = 0;
  for (size_t i = 0; i < texels; ++i) {
    const float z = frame.depth[i];
    switch (classify_depth(z)) {
      case DepthClass::kFinite:
        lo = std::min(lo, z);
        hi = std::max(hi, z);
        break;
      case DepthClass::kSky:
        break;
      case DepthClass::kInvalid: {
        const size_t face_texels = size_t{n} * n;
        const size_t in_face = i % face_texels;
        return views_error(
            context, std::string("depth ") + std::to_string(z) + " at face " +
                         cube_face_name(cube_face_from_index(static_cast<int>(i / face_texels))) +
                         " texel (" + std::to_string(in_face % n) + ", " +
                         std::to_string(in_face / n) + ") is not a distance (NaN, -inf or <= 0)");
      }
    }
  }
  Expected<LogDepthRange> range =
      hi > 0 ? LogDepthRange::covering(lo, hi) : LogDepthRange::make(1, 2);
  if (!range.ok()) return std::move(range).status().with_context(context);
  CALF_ASSIGN_OR_RETURN(View view, View::make(position, *range, n, frame.has_material));
  const PixelRect whole{0, 0, n, n};
  const size_t face_texels = size_t{n} * n;
  std::vector<uint16_t> codes(face_texels);
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    const size_t first = f * face_texels;
    for (size_t i = 0; i < face_texels; ++i)
      codes[i] = range->encode_unchecked(frame.depth[first + i]);
    Status s = view.write_depth_rect(face, whole, codes);
    if (s.ok()) {
      s = view.write_colour_rect(
          face, whole, std::span<const float>(frame.color).subspan(3 * first, 3 * face_texels));
    }
    if (s.ok() && frame.has_material) {
      s = view.write_material_rect(
          face, whole, std::span<const float>(frame.material).subspan(3 * first, 3 * face_texels));
    }
    if (s.ok() && frame.has_coverage) {
      view.add_coverage();
      s = view.write_coverage_rect(
          face, whole, std::span<const float>(frame.coverage).subspan(3 * first, 3 * face_texels));
    }
    if (!s.ok()) return std::move(s).with_context(context);
  }
  return view;
}

Expected<ViewSet> load_capture_views(const capture::CaptureSetReader& reader, uint32_t frame) {
  const capture::CaptureManifest& m = reader.manifest();
  if (frame >= m.frame_count) {
    return views_error(reader.directory().string(), "frame " + std::to_string(frame) +
                                                        " is outside the capture set's " +
                                                        std::to_string(m.frame_count) + " frames");
  }
  ViewSet views;
  views.views.reserve(m.viewpoints.size());
  capture::ViewFrame image;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    CALF_RETURN_IF_ERROR(reader.read(v, frame, &image));
    CALF_ASSIGN_OR_RETURN(View view, view_from_capture_frame(image, m.viewpoints[v].position,
                                                             reader.image_path(v, frame).string()));
    views.views.push_back(std::move(view));
  }
  return views;
}

uint32_t capture_frame_at(const capture::CaptureManifest& manifest, double time) {
  const double f = std::round(time * manifest.fps);
  if (!(f > 0) || manifest.frame_count == 0) return 0;  // also NaN
  return static_cast<uint32_t>(std::min(f, static_cast<double>(manifest.frame_count - 1)));
}

RenderedImage reproject_view(const View& view, const Camera& camera) {
  RenderedImage out;
  out.width = camera.width;
  out.height = camera.height;
  const size_t pixels = size_t{camera.width} * camera.height;
  out.color.assign(3 * pixels, 0.0f);
  out.depth.assign(pixels, 0.0f);
  const uint32_t n = view.face_size();
  const CameraFrame frame = camera_frame(camera);
  for (uint32_t j = 0; j < camera.height; ++j) {
    for (uint32_t i = 0; i < camera.width; ++i) {
      const Vec3 dir = camera_ray(camera, frame, i, j);
      const internal::BilinearTaps taps =
          internal::bilinear_taps(texel_coord_from_direction(dir, n), n);
      const size_t k = size_t{j} * camera.width + i;
      double c[3] = {0, 0, 0};
      for (int t = 0; t < 4; ++t) {
        const float* col = view.colour_at(taps.texel[t].face, taps.texel[t].x, taps.texel[t].y);
        for (int ch = 0; ch < 3; ++ch) c[ch] += taps.weight[t] * col[ch];
      }
      for (int ch = 0; ch < 3; ++ch) out.color[3 * k + ch] = static_cast<float>(c[ch]);
      const Texel nearest = texel_from_direction(dir, n);
      out.depth[k] = view.range().decode(view.depth_code_at(nearest.face, nearest.x, nearest.y));
    }
  }
  return out;
}

}  // namespace calf::player
