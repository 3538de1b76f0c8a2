#include "calf/player/playback.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "calf/capture/eye_path.h"
#include "calf/format/container.h"
#include "kind_table.h"

namespace calf::player {

struct Playback::Impl {
  // Declared first, destroyed last: the representations read from it.
  std::unique_ptr<container::Reader> reader;
  PlaybackOptions options;
  std::vector<std::unique_ptr<Representation>> owned;
  std::vector<Representation*> representations;
  LightfieldRepresentation* lightfield = nullptr;
  Box3 volume;
  RenderedImage layer;  // scratch for the second and later representations
  double render_ms = 0;
};

Playback::Playback(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Playback::~Playback() = default;

Expected<std::unique_ptr<Playback>> Playback::open(const std::string& clip_path,
                                                   const PlaybackOptions& options,
                                                   const GlFunctions* gl) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(clip_path));
  impl->reader = std::make_unique<container::Reader>(std::move(reader));
  const RenderBackend backend = options.use_gl ? RenderBackend::kGl : RenderBackend::kCpu;
  // Each track through its kind's entry in the player table (kind_table.h). The kinds whose
  // representation plays other tracks too (a surfels track its paired mesh track) are opened
  // first, in track order; then the others, in track order, but for the tracks already played.
  const auto& tracks = impl->reader->tracks();
  std::vector<bool> claimed(tracks.size(), false);
  for (const bool first_pass : {true, false}) {
    for (size_t t = 0; t < tracks.size(); ++t) {
      const PlayerKind* kind = find_player_kind(tracks[t].record.kind);
      if (kind == nullptr || kind->claims_tracks != first_pass || claimed[t]) continue;
      CALF_ASSIGN_OR_RETURN(
          OpenedRepresentation opened,
          kind->open(*impl->reader, static_cast<uint16_t>(t), options, backend, gl));
      for (const uint16_t other : opened.claimed_tracks) {
        if (other < claimed.size()) claimed[other] = true;
      }
      if (impl->lightfield == nullptr && kind->kind == container::TrackKind::kLightfield) {
        impl->lightfield = static_cast<LightfieldRepresentation*>(opened.representation.get());
      }
      impl->owned.push_back(std::move(opened.representation));
    }
  }
  if (impl->owned.empty()) {
    return Status(ErrorId::kPlaybackClip,
                  clip_path + ": no lightfield, tiles, mesh or surfels track to play");
  }
  impl->volume = impl->owned.front()->view_volume();
  for (const auto& r : impl->owned) {
    impl->representations.push_back(r.get());
    impl->volume = box_union(impl->volume, r->view_volume());
  }
  return std::unique_ptr<Playback>(new Playback(std::move(impl)));
}

uint32_t Playback::frame_count() const {
  return impl_->representations.front()->frame_count();
}
double Playback::fps() const {
  return impl_->representations.front()->fps();
}

uint32_t Playback::frame_at_time(double seconds) const {
  return capture::frame_at_time(seconds, fps(), frame_count());
}

const Box3& Playback::view_volume() const {
  return impl_->volume;
}

bool Playback::inside_view_volume(const Vec3& p) const {
  const auto& [lo, hi] = impl_->volume;
  constexpr double kSlack = 1e-9;
  return p.x >= lo.x - kSlack && p.y >= lo.y - kSlack && p.z >= lo.z - kSlack &&
         p.x <= hi.x + kSlack && p.y <= hi.y + kSlack && p.z <= hi.z + kSlack;
}

std::span<Representation* const> Playback::representations() const {
  return impl_->representations;
}
LightfieldRepresentation* Playback::lightfield() const {
  return impl_->lightfield;
}
const PlaybackOptions& Playback::options() const {
  return impl_->options;
}
double Playback::last_render_ms() const {
  return impl_->render_ms;
}

std::vector<RepresentationStats> Playback::stats() const {
  std::vector<RepresentationStats> out;
  for (const Representation* r : impl_->representations) out.push_back(r->stats());
  return out;
}

FrameFigures Playback::figures() const {
  FrameFigures out;
  for (const Representation* r : impl_->representations) {
    const FrameFigures f = r->figures();
    out.triangles_drawn += f.triangles_drawn;
    if (!out.quads) out.quads = f.quads;
    if (!out.points) out.points = f.points;
  }
  return out;
}

Status Playback::prepare(uint32_t frame, std::span<const Camera> eyes) {
  if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
  for (Representation* r : impl_->representations) {
    CALF_RETURN_IF_ERROR(r->prepare(std::min(frame, r->frame_count() - 1), eyes));
  }
  return Status::Ok();
}

Status Playback::render(const Camera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  // The first representation renders straight into `out`: with one track nothing else touches it.
  CALF_RETURN_IF_ERROR(d.representations.front()->render(camera, out));
  for (size_t i = 1; i < d.representations.size(); ++i) {
    CALF_RETURN_IF_ERROR(d.representations[i]->render(camera, &d.layer));
    CALF_RETURN_IF_ERROR(composite_nearest(d.layer, out));
  }
  d.render_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return Status::Ok();
}

Status Playback::report_frame_time(double frame_ms) {
  for (Representation* r : impl_->representations) {
    CALF_RETURN_IF_ERROR(r->report_frame_time(frame_ms));
  }
  return Status::Ok();
}

}  // namespace calf::player
