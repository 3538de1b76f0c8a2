#include <filesystem>
#include <string>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/format/av1_hdr_colour.h"
#include "calf/format/clip_metadata.h"
#include "calf/format/files.h"
#include "calf/format/version.h"
#include "lightfield_internal.h"
#include "lightfield_view_pass.h"

namespace calf::encoder {

using container::ChunkKeys;
using lightfield_internal::add_figures;
using lightfield_internal::kInf;

Expected<LightfieldTrackWriter> LightfieldTrackWriter::begin(container::Writer& writer,
                                                             const LightfieldAnalysis& analysis) {
  CALF_ASSIGN_OR_RETURN(uint16_t track, writer.add_track(analysis.header));
  // A coverage stream is a 1.2 feature (SPEC §11.1.11): the file says so in its minor version.
  if (analysis.coverage) writer.require_minor_version(container::kVersionMinorCoverage);
  // So is AV1 colour (1.3, SPEC §11.1.12), which earlier decoders refuse as an unknown format.
  // HDR AV1 colour is 1.4, 4:4:4 AV1 colour 1.5.
  if (analysis.colour == ColourCoding::kAv1) {
    writer.require_minor_version(lf::is_av1_chroma444(analysis.header.colour_format)
                                     ? container::kVersionMinorAv1Chroma444
                                 : analysis.hdr ? container::kVersionMinorAv1Hdr
                                                : container::kVersionMinorAv1);
  }
  LightfieldEncodeStats stats;
  stats.colour_format = analysis.header.colour_format;
  stats.depth_format = analysis.header.depth_format;
  stats.material_format = analysis.header.material_format;
  stats.hdr = analysis.hdr;
  stats.min_colour_quality_db = kInf;
  return LightfieldTrackWriter(writer, track, analysis.header.view_count, stats);
}

Status LightfieldTrackWriter::append(const LightfieldViewEncoding& view) {
  if (view.view != next_view_ || next_view_ >= view_count_) {
    return Status(ErrorId::kEncoderInput, "view " + std::to_string(view.view) +
                                              " appended where view " + std::to_string(next_view_) +
                                              " of " + std::to_string(view_count_) + " comes next");
  }
  for (const LightfieldChunk& c : view.chunks) {
    ChunkKeys keys = c.keys;
    keys.track = track_;
    CALF_RETURN_IF_ERROR(writer_->add_stored_chunk(keys, c.chunk).status());
  }
  next_view_ += 1;
  add_figures(stats_, view.stats);
  return Status::Ok();
}

Expected<LightfieldEncodeStats> LightfieldTrackWriter::finish() const {
  if (next_view_ != view_count_) {
    return Status(ErrorId::kEncoderInput, "the track has " + std::to_string(next_view_) +
                                              " of its " + std::to_string(view_count_) + " views");
  }
  return stats_;
}

Expected<LightfieldEncodeStats> encode_lightfield(const capture::CaptureSetReader& input,
                                                  container::Writer& writer,
                                                  const LightfieldEncodeOptions& options) {
  CALF_ASSIGN_OR_RETURN(const LightfieldAnalysis analysis, analyse_lightfield(input, options));
  CALF_ASSIGN_OR_RETURN(LightfieldTrackWriter track,
                        LightfieldTrackWriter::begin(writer, analysis));
  for (uint32_t v = 0; v < analysis.header.view_count; ++v) {
    CALF_ASSIGN_OR_RETURN(const LightfieldViewEncoding view,
                          encode_lightfield_view(input, analysis, v, options));
    CALF_RETURN_IF_ERROR(track.append(view));
  }
  return track.finish();
}

Expected<LightfieldEncodeStats> encode_lightfield_file(const std::filesystem::path& capture_dir,
                                                       const std::string& out_path,
                                                       const LightfieldEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader input,
                        capture::CaptureSetReader::open(capture_dir, options.max_image_pixels));
  // The output must not be one of the inputs: renaming over the manifest or an image would
  // destroy the set the clip is made from (CALF-E007; the directory itself is E004's).
  std::vector<std::string> inputs = {capture_dir.string(),
                                     (capture_dir / capture::kManifestFileName).string()};
  for (uint32_t v = 0; v < input.manifest().viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < input.manifest().frame_count; ++f)
      inputs.push_back(input.image_path(v, f).string());
  }
  CALF_RETURN_IF_ERROR(files::check_output_not_input(out_path, inputs));
  CALF_ASSIGN_OR_RETURN(container::Writer writer,
                        container::Writer::create(out_path, options.levels));
  CALF_ASSIGN_OR_RETURN(LightfieldEncodeStats stats, encode_lightfield(input, writer, options));
  CALF_RETURN_IF_ERROR(
      writer.set_metadata("encoder", std::string("calf-encode ") + kVersionString));
  if (!input.manifest().scene.empty()) {
    CALF_RETURN_IF_ERROR(writer.set_metadata("source_scene", input.manifest().scene));
  }
  // The box the eye may move in (format/CAPTURE.md view_volume): the player warns outside it.
  CALF_RETURN_IF_ERROR(
      writer.set_metadata(std::string(container::kViewVolumeKey),
                          container::format_view_volume(input.manifest().view_volume)));
  CALF_RETURN_IF_ERROR(writer.finish());
  return stats;
}

}  // namespace calf::encoder