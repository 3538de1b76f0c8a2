// The swatch kind's representation and its entry in the player table (player/src/kind_table.h):
// every pixel of a render takes the frame's colour at the sky's depth (+inf), so any other track
// drawn with it covers it. Both backends render on the CPU (the image is one colour).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/track_registry.h"
#include "kind_table.h"

namespace calf::player {
namespace {

class SwatchRepresentation final : public Representation {
 public:
  SwatchRepresentation(const container::Reader& reader, uint16_t track,
                       const container::SwatchTrackHeader& header, RenderBackend backend)
      : reader_(reader), track_(track), header_(header), backend_(backend) {}

  std::string_view kind() const override { return "swatch"; }
  uint16_t track() const override { return track_; }
  RenderBackend backend() const override { return backend_; }
  uint32_t frame_count() const override { return header_.frame_count; }
  double fps() const override {
    return static_cast<double>(header_.fps_numerator) /
           static_cast<double>(header_.fps_denominator);
  }
  const Box3& view_volume() const override { return view_volume_; }

  // Reads the frame's colour chunk (the last frame's past the end).
  Status prepare(uint32_t frame, std::span<const Camera> eyes) override {
    if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
    container::ChunkQuery q;
    q.track = track_;
    q.stream = static_cast<uint16_t>(container::SwatchStream::kColour);
    q.frame = std::min(frame, header_.frame_count - 1);
    const std::vector<uint32_t> ids = reader_.find_chunks(q);
    const std::string what = "track " + std::to_string(track_) + " swatch colour";
    if (ids.size() != 1)
      return Status(ErrorId::kInvalidArgument, what + ": " + std::to_string(ids.size()) +
                                                   " chunks for frame " + std::to_string(*q.frame));
    CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_.read_chunk(ids[0]));
    CALF_ASSIGN_OR_RETURN(colour_, swatch::parse<swatch::ColourChunk>(raw, what));
    return Status::Ok();
  }

  Status render(const Camera& camera, RenderedImage* out) override {
    CALF_RETURN_IF_ERROR(validate_camera(camera));
    const size_t pixels = size_t{camera.width} * camera.height;
    out->width = camera.width;
    out->height = camera.height;
    out->color.resize(3 * pixels);
    for (size_t i = 0; i < pixels; ++i) {
      out->color[3 * i + 0] = static_cast<float>(colour_.r) / 255.0f;
      out->color[3 * i + 1] = static_cast<float>(colour_.g) / 255.0f;
      out->color[3 * i + 2] = static_cast<float>(colour_.b) / 255.0f;
    }
    out->depth.assign(pixels, std::numeric_limits<float>::infinity());
    return Status::Ok();
  }

  Status report_frame_time(double frame_ms) override {
    if (!(std::isfinite(frame_ms) && frame_ms >= 0))
      return Status(ErrorId::kPlayerOptions, "frame time is negative or not finite");
    return Status::Ok();
  }

  RepresentationStats stats() const override {
    return {"swatch track " + std::to_string(track_),
            {{"colour", std::to_string(colour_.r) + " " + std::to_string(colour_.g) + " " +
                            std::to_string(colour_.b)}}};
  }

 private:
  const container::Reader& reader_;
  uint16_t track_;
  container::SwatchTrackHeader header_;
  RenderBackend backend_;
  Box3 view_volume_{};
  swatch::ColourChunk colour_{};
};

Expected<OpenedRepresentation> open(const container::Reader& reader, uint16_t track,
                                    const PlaybackOptions& /*options*/, RenderBackend backend,
                                    const GlFunctions* /*gl*/) {
  const auto* header = std::get_if<container::SwatchTrackHeader>(&reader.tracks()[track].header);
  if (header == nullptr) return Status(ErrorId::kInvalidArgument, "not a swatch track");
  OpenedRepresentation out;
  out.representation = std::make_unique<SwatchRepresentation>(reader, track, *header, backend);
  return out;
}

}  // namespace

extern const PlayerKind kSwatchPlayerKind = {
    .kind = container::TrackKind::kSwatch,
    .claims_tracks = false,
    .open = open,
};

}  // namespace calf::player
