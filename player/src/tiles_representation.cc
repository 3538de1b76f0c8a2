// The tiles representation; what it does is in the public header.
#include "calf/player/tiles_representation.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>

#include "calf/decoder/tiles_track.h"

namespace calf::player {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string format(const char* fmt, auto... args) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace

struct TilesRepresentation::Impl {
  uint16_t track = 0;
  RenderBackend backend = RenderBackend::kGl;
  TilesOptions options;
  double fps = 24;
  TileSet set;
  TilesLinearAtlas atlas;  // the CPU backend's; the GL one keeps it on the GPU only
  std::unique_ptr<GlTilesRenderer> gl;
  TilesFrameStats frame_stats;
  double render_ms = 0;
};

TilesRepresentation::TilesRepresentation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TilesRepresentation::~TilesRepresentation() = default;

Expected<std::unique_ptr<TilesRepresentation>> TilesRepresentation::make(
    TileSet tiles, uint16_t track, double fps, const TilesOptions& options, RenderBackend backend,
    const GlFunctions* gl) {
  CALF_RETURN_IF_ERROR(validate_tiles_render_options(options.render));
  CALF_RETURN_IF_ERROR(validate_tile_set(tiles));
  if (!(std::isfinite(fps) && fps > 0)) {
    return Status(ErrorId::kTilesDraw, "tiles track " + std::to_string(track) + ": frame rate " +
                                           std::to_string(fps) + " is not > 0");
  }
  auto impl = std::make_unique<Impl>();
  impl->track = track;
  impl->backend = backend;
  impl->options = options;
  impl->fps = fps;
  impl->set = std::move(tiles);
  impl->atlas = tiles_linear_atlas(impl->set);
  if (backend == RenderBackend::kGl) {
    if (gl == nullptr) {
      return Status(ErrorId::kPlayerGl, "the GL tiles renderer needs a current OpenGL 4.5 context");
    }
    CALF_ASSIGN_OR_RETURN(impl->gl, GlTilesRenderer::make(*gl));
    CALF_RETURN_IF_ERROR(impl->gl->upload(impl->set, impl->atlas));
    impl->atlas = TilesLinearAtlas{};  // on the GPU now
  }
  return std::unique_ptr<TilesRepresentation>(new TilesRepresentation(std::move(impl)));
}

Expected<std::unique_ptr<TilesRepresentation>> TilesRepresentation::open(
    const container::Reader& reader, uint16_t track, const TilesOptions& options,
    RenderBackend backend, const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(TileSet tiles, decoder::decode_tiles_track(reader, track));
  const auto& header = std::get<container::TilesTrackHeader>(reader.tracks()[track].header);
  const double fps =
      static_cast<double>(header.fps_numerator) / static_cast<double>(header.fps_denominator);
  return make(std::move(tiles), track, fps, options, backend, gl);
}

std::string_view TilesRepresentation::kind() const {
  return "tiles";
}
uint16_t TilesRepresentation::track() const {
  return impl_->track;
}
RenderBackend TilesRepresentation::backend() const {
  return impl_->backend;
}
uint32_t TilesRepresentation::frame_count() const {
  return 1;
}
double TilesRepresentation::fps() const {
  return impl_->fps;
}
const Box3& TilesRepresentation::view_volume() const {
  return impl_->set.view_volume;
}
const TileSet& TilesRepresentation::tile_set() const {
  return impl_->set;
}
const TilesFrameStats& TilesRepresentation::last_frame_stats() const {
  return impl_->frame_stats;
}
double TilesRepresentation::last_render_ms() const {
  return impl_->render_ms;
}

Status TilesRepresentation::prepare(uint32_t frame, std::span<const Camera> eyes) {
  if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
  if (frame != 0) {
    return Status(ErrorId::kTilesDraw,
                  "frame " + std::to_string(frame) + " is past the tiles track's single frame");
  }
  return Status::Ok();
}

Status TilesRepresentation::render(const Camera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  if (d.gl) {
    CALF_RETURN_IF_ERROR(d.gl->render(d.set, camera, d.options.render, out, &d.frame_stats));
  } else {
    CALF_RETURN_IF_ERROR(
        render_tiles_cpu(d.set, d.atlas, camera, d.options.render, out, &d.frame_stats));
  }
  d.render_ms = ms_since(t0);
  return Status::Ok();
}

Status TilesRepresentation::report_frame_time(double frame_ms) {
  if (!(std::isfinite(frame_ms) && frame_ms >= 0)) {
    return Status(ErrorId::kViewSelectFrameTime,
                  "frame time " + std::to_string(frame_ms) + " ms is negative or not finite");
  }
  return Status::Ok();
}

FrameFigures TilesRepresentation::figures() const {
  const TilesFrameStats& s = last_frame_stats();
  FrameFigures f;
  f.quads = FrameFigures::Quads{.count = tile_set().tiles.size(),
                                .mean_overdraw = s.mean_overdraw(),
                                .peak_overdraw = s.peak};
  return f;
}

RepresentationStats TilesRepresentation::stats() const {
  const Impl& d = *impl_;
  RepresentationStats out;
  out.title =
      format("tiles track %u (%s)", d.track, d.backend == RenderBackend::kGl ? "gl" : "cpu");
  const size_t n = d.set.tiles.size();
  out.entries.push_back({"tiles", format("%zu", n)});
  out.entries.push_back({"triangles", format("%zu", 2 * n)});
  const TilesFrameStats& f = d.frame_stats;
  out.entries.push_back({"overdraw", f.measured
                                         ? format("%.2f mean, %u peak", f.mean_overdraw(), f.peak)
                                         : std::string("not measured")});
  out.entries.push_back(
      {"atlas", format("%u x %u (%.1f Mtexels)", d.set.atlas_width, d.set.atlas_height,
                       1e-6 * d.set.atlas_width * d.set.atlas_height)});
  out.entries.push_back({"blend", std::string(tiles_blend_name(d.options.render.blend))});
  out.entries.push_back({"draw", format("%.1f ms", d.render_ms)});
  return out;
}

}  // namespace calf::player
