// Sharded light-field encoding: the analysis file, shard files and their merge
// (lightfield_shard.h, docs/FARM.md).
#include "calf/encoder/lightfield_shard.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "calf/capture/capture_shard.h"
#include "calf/encoder/colour_denoise.h"
#include "calf/format/clip_metadata.h"
#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/container_fields.h"
#include "calf/format/files.h"
#include "calf/format/version.h"
#include "lightfield_internal.h"

namespace calf::encoder {
namespace {

// Metadata keys of the intermediate files. Their record is text: one fact per line, floats as
// C99 hex literals ("%a"), so that they parse back to the same bits on any machine.
constexpr const char* kAnalysisKey = "calf.lightfield_analysis";
constexpr const char* kAnalysisIdKey = "calf.lightfield_analysis_id";
constexpr const char* kShardViewsKey = "calf.lightfield_shard_views";
constexpr const char* kShardFramesKey = "calf.lightfield_shard_frames";  // "first-last"
constexpr const char* kRecordMagic = "calf-lightfield-analysis 8";
constexpr const char* kRecordMagicPrefix = "calf-lightfield-analysis ";

std::string hex_double(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// The record: options that change the bytes, the resolved colour format, every view's facts and
// the fingerprints of its images' bytes (one per segment of frames).
std::string analysis_record(const LightfieldAnalysis& a, const LightfieldEncodeOptions& o,
                            const std::vector<std::vector<uint64_t>>& pixels) {
  std::ostringstream s;
  s << kRecordMagic << "\n";
  s << "cell " << o.cell_size << "\npsnr " << hex_double(o.min_psnr_db) << "\nnoise_psnr "
    << hex_double(o.noise_psnr_db) << "\nnoise_factor " << hex_double(o.noise_factor)
    << "\ndenoise_window " << o.denoise_window << "\ncolour " << static_cast<int>(o.colour)
    << "\ndepth " << static_cast<int>(o.depth) << "\ntiles " << o.depth_regions_per_side
    << "\nwindow " << o.depth_window << "\naabbs " << o.max_aabbs << "\nkeyframe_interval "
    << o.depth_keyframe_interval << "\nsupercompression " << static_cast<int>(o.supercompression)
    << "\nzstd_level " << o.levels.zstd_level << "\nlzma_preset " << o.levels.lzma_preset
    << "\nsegment_frames " << o.segment_frames << "\nmerge_static_groups "
    << (o.merge_static_groups ? 1 : 0) << "\ncolour_rdo " << hex_double(o.colour_rdo)
    << "\nbc1_fit " << static_cast<int>(o.bc1_fit) << "\ncoverage " << (o.coverage ? 1 : 0)
    << "\ncoverage_unmix " << (o.coverage_unmix ? 1 : 0) << " "
    << hex_double(o.coverage_unmix ? o.coverage_unmix->min_share : 0.0) << " "
    << hex_double(o.coverage_unmix ? o.coverage_unmix->min_jump : 0.0) << "\nresolved_colour "
    << static_cast<int>(a.colour) << "\ncoverage_stream " << (a.coverage ? 1 : 0) << "\nviews "
    << a.views.size() << "\n";
  for (size_t v = 0; v < a.views.size(); ++v) {
    const LightfieldViewFacts& f = a.views[v];
    s << "view " << v << " " << (f.depth_range ? 1 : 0) << " "
      << hex_double(f.depth_range ? f.depth_range->z_near() : 0.0) << " "
      << hex_double(f.depth_range ? f.depth_range->z_far() : 0.0) << " " << (f.has_material ? 1 : 0)
      << " " << (f.hdr ? 1 : 0) << "\n";
  }
  for (size_t v = 0; v < pixels.size(); ++v) {
    s << "pixels " << v << " " << pixels[v].size();
    for (const uint64_t h : pixels[v]) {
      char buf[24];
      std::snprintf(buf, sizeof buf, " %016" PRIx64, h);
      s << buf;
    }
    s << "\n";
  }
  return s.str();
}

Status bad_record(const std::string& path, const std::string& what) {
  return Status(ErrorId::kShardFile, path + ": not a calf analysis file: " + what);
}

// Parses one "key value" line into an unsigned value bounded by `max`.
bool read_uint(std::istringstream& in, const char* key, uint64_t max, uint64_t* out) {
  std::string k, v;
  if (!(in >> k >> v) || k != key || v.empty() || v.size() > 20) return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long x = std::strtoull(v.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v[0] == '-' || x > max) return false;
  *out = x;
  return true;
}

bool read_double(std::istringstream& in, double* out) {
  std::string v;
  if (!(in >> v) || v.size() > 40) return false;
  char* end = nullptr;
  *out = std::strtod(v.c_str(), &end);
  return *end == '\0';
}

// The record back into options and facts; the analysis itself is planned again from them, so a
// record that does not fit its own header is refused.
Status parse_record(const std::string& path, const std::string& text, LightfieldEncodeOptions* o,
                    uint64_t* resolved_colour, bool* coverage_stream,
                    std::vector<LightfieldViewFacts>* facts,
                    std::vector<std::vector<uint64_t>>* pixels) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) return bad_record(path, "unknown record");
  if (line != kRecordMagic) {
    if (line.rfind(kRecordMagicPrefix, 0) == 0 && line.size() < 40) {
      return bad_record(path, "record version '" + line.substr(std::strlen(kRecordMagicPrefix)) +
                                  "' is not this calf's " +
                                  std::string(kRecordMagic + std::strlen(kRecordMagicPrefix)) +
                                  " (an analysis file of another calf version: write it again "
                                  "with calf-encode --analysis-only)");
    }
    return bad_record(path, "unknown record");
  }
  uint64_t x = 0;
  auto field = [&](const char* key, uint64_t max) -> bool {
    if (!read_uint(in, key, max, &x)) return false;
    return true;
  };
  if (!field("cell", UINT32_MAX)) return bad_record(path, "cell");
  o->cell_size = static_cast<uint32_t>(x);
  std::string key;
  if (!(in >> key) || key != "psnr" || !read_double(in, &o->min_psnr_db)) {
    return bad_record(path, "psnr");
  }
  if (!(in >> key) || key != "noise_psnr" || !read_double(in, &o->noise_psnr_db)) {
    return bad_record(path, "noise_psnr");
  }
  if (!(in >> key) || key != "noise_factor" || !read_double(in, &o->noise_factor)) {
    return bad_record(path, "noise_factor");
  }
  if (!field("denoise_window", kMaxDenoiseWindow)) return bad_record(path, "denoise_window");
  o->denoise_window = static_cast<uint32_t>(x);
  if (!field("colour", static_cast<uint64_t>(ColourCoding::kRgba16f)))
    return bad_record(path, "colour");
  o->colour = static_cast<ColourCoding>(x);
  if (!field("depth", static_cast<uint64_t>(DepthCoding::kRaw16PredictedMasked)))
    return bad_record(path, "depth");
  o->depth = static_cast<DepthCoding>(x);
  if (!field("tiles", 64)) return bad_record(path, "tiles");
  o->depth_regions_per_side = static_cast<uint32_t>(x);
  if (!field("window", 65535)) return bad_record(path, "window");
  o->depth_window = static_cast<uint32_t>(x);
  if (!field("aabbs", 64)) return bad_record(path, "aabbs");
  o->max_aabbs = static_cast<uint32_t>(x);
  if (!field("keyframe_interval", UINT32_MAX)) return bad_record(path, "keyframe_interval");
  o->depth_keyframe_interval = static_cast<uint32_t>(x);
  if (!field("supercompression", container::kCompressionCount - 1))
    return bad_record(path, "supercompression");
  o->supercompression = static_cast<container::Compression>(x);
  if (!field("zstd_level", 22)) return bad_record(path, "zstd_level");
  o->levels.zstd_level = static_cast<int>(x);
  if (!field("lzma_preset", 9)) return bad_record(path, "lzma_preset");
  o->levels.lzma_preset = static_cast<uint32_t>(x);
  if (!field("segment_frames", UINT32_MAX)) return bad_record(path, "segment_frames");
  o->segment_frames = static_cast<uint32_t>(x);
  if (!field("merge_static_groups", 1)) return bad_record(path, "merge_static_groups");
  o->merge_static_groups = x != 0;
  if (!(in >> key) || key != "colour_rdo" || !read_double(in, &o->colour_rdo)) {
    return bad_record(path, "colour_rdo");
  }
  if (!field("bc1_fit", static_cast<uint64_t>(Bc1Fit::kCluster)))
    return bad_record(path, "bc1_fit");
  o->bc1_fit = static_cast<Bc1Fit>(x);
  if (!field("coverage", 1)) return bad_record(path, "coverage");
  o->coverage = x != 0;
  if (!field("coverage_unmix", 1)) return bad_record(path, "coverage_unmix");
  {
    capture::CoverageUnmixOptions u;
    if (!read_double(in, &u.min_share) || !read_double(in, &u.min_jump)) {
      return bad_record(path, "coverage_unmix");
    }
    if (x != 0) o->coverage_unmix = u;
  }
  if (!field("resolved_colour", static_cast<uint64_t>(ColourCoding::kRgba16f)))
    return bad_record(path, "resolved_colour");
  *resolved_colour = x;
  if (!field("coverage_stream", 1)) return bad_record(path, "coverage_stream");
  *coverage_stream = x != 0;
  if (!field("views", container::kMaxViews)) return bad_record(path, "views");
  const uint64_t n = x;
  facts->assign(n, {});
  for (uint64_t v = 0; v < n; ++v) {
    const std::string what = "view " + std::to_string(v);
    uint64_t index = 0, has_range = 0, material = 0, hdr = 0;
    double z_near = 0, z_far = 0;
    if (!read_uint(in, "view", UINT32_MAX, &index) || index != v || !(in >> has_range) ||
        !read_double(in, &z_near) || !read_double(in, &z_far) || !(in >> material >> hdr) ||
        has_range > 1 || material > 1 || hdr > 1) {
      return bad_record(path, what);
    }
    LightfieldViewFacts& f = (*facts)[v];
    f.has_material = material == 1;
    f.hdr = hdr == 1;
    if (has_range) {
      // Checked before the conversion: a double beyond float's range has no float value.
      if (!(z_near > 0 && z_near <= std::numeric_limits<float>::max() && z_far > 0 &&
            z_far <= std::numeric_limits<float>::max())) {
        return bad_record(path, what + ": depth range outside float's");
      }
      Expected<LogDepthRange> r =
          LogDepthRange::make(static_cast<float>(z_near), static_cast<float>(z_far));
      if (!r.ok()) return bad_record(path, what + ": " + r.status().message());
      f.depth_range = *r;
    }
  }
  pixels->assign(n, {});
  for (uint64_t v = 0; v < n; ++v) {
    const std::string what = "pixels of view " + std::to_string(v);
    uint64_t index = 0, count = 0;
    if (!read_uint(in, "pixels", UINT32_MAX, &index) || index != v || !(in >> count) ||
        count == 0 || count > container::kMaxFrames || count > text.size() / 17) {
      return bad_record(path, what);
    }
    auto& hashes = (*pixels)[v];
    hashes.resize(count);
    for (uint64_t& h : hashes) {
      std::string hex;
      if (!(in >> hex) || hex.size() != 16) return bad_record(path, what);
      char* end = nullptr;
      errno = 0;
      h = std::strtoull(hex.c_str(), &end, 16);
      if (errno != 0 || *end != '\0' || hex[0] == '-' || hex[0] == '+') {
        return bad_record(path, what);
      }
    }
  }
  std::string rest;
  if (in >> rest) return bad_record(path, "trailing text");
  return Status::Ok();
}

std::string id_of(const std::string& record, std::span<const uint8_t> header) {
  std::vector<uint8_t> bytes(record.begin(), record.end());
  bytes.insert(bytes.end(), header.begin(), header.end());
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016" PRIx64,
                container::hash64(std::span<const uint8_t>(bytes.data(), bytes.size())));
  return buf;
}

// The clip's metadata, as encode_lightfield_file() writes it.
std::vector<std::pair<std::string, std::string>> clip_metadata(const capture::CaptureManifest& m) {
  std::vector<std::pair<std::string, std::string>> md;
  md.emplace_back("encoder", std::string("calf-encode ") + kVersionString);
  if (!m.scene.empty()) md.emplace_back("source_scene", m.scene);
  md.emplace_back(std::string(container::kViewVolumeKey),
                  container::format_view_volume(m.view_volume));
  return md;
}

constexpr const char* kClipMetadataPrefix = "calf.clip.";

// Every image of the set plus its directory and manifest, and the analysis file a shard is coded
// with: what an output must not be.
std::vector<std::string> capture_inputs(const capture::CaptureSetReader& input,
                                        const std::string& analysis_path = {}) {
  std::vector<std::string> inputs = {input.directory().string(),
                                     (input.directory() / capture::kManifestFileName).string()};
  for (uint32_t v = 0; v < input.manifest().viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < input.manifest().frame_count; ++f)
      inputs.push_back(input.image_path(v, f).string());
  }
  if (!analysis_path.empty()) inputs.push_back(analysis_path);
  return inputs;
}

// Frames per fingerprint: a segment of --segment-frames, or the whole clip.
uint32_t pixel_segment(const LightfieldEncodeOptions& o, uint32_t frame_count) {
  return o.segment_frames ? o.segment_frames : frame_count;
}

// XXH3-64 of a whole image file's bytes.
Expected<uint64_t> file_hash(const std::string& path) {
  CALF_ASSIGN_OR_RETURN(const int fd, files::open_regular_file(path));
  std::vector<uint8_t> bytes;
  uint8_t buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      return Status(ErrorId::kFileRead, path + ": " + std::strerror(e));
    }
    if (n == 0) break;
    bytes.insert(bytes.end(), buf, buf + n);
  }
  ::close(fd);
  return container::hash64(bytes);
}

// The fingerprint of view `v`'s frames [first, first + count): XXH3-64 of their files' hashes,
// 8 bytes each, little-endian, in frame order.
Expected<uint64_t> pixels_of(const capture::CaptureSetReader& input, uint32_t v, uint32_t first,
                             uint32_t count) {
  std::vector<uint8_t> hashes;
  for (uint32_t f = first; f < first + count; ++f) {
    CALF_ASSIGN_OR_RETURN(const uint64_t h, file_hash(input.image_path(v, f).string()));
    const size_t at = hashes.size();
    hashes.resize(at + 8);
    container::store_le(hashes.data() + at, h, 8);
  }
  return container::hash64(hashes);
}

// Every view's fingerprints, one per segment of frames.
Expected<std::vector<std::vector<uint64_t>>> capture_pixels(const capture::CaptureSetReader& input,
                                                            const LightfieldEncodeOptions& o) {
  const uint32_t frames = input.manifest().frame_count;
  const uint32_t segment = pixel_segment(o, frames);
  std::vector<std::vector<uint64_t>> out(input.manifest().viewpoints.size());
  for (uint32_t v = 0; v < out.size(); ++v) {
    for (uint32_t first = 0; first < frames; first += segment) {
      CALF_ASSIGN_OR_RETURN(const uint64_t h,
                            pixels_of(input, v, first, std::min(segment, frames - first)));
      out[v].push_back(h);
    }
  }
  return out;
}

}  // namespace

Expected<LightfieldAnalysisFile> write_lightfield_analysis(const std::filesystem::path& capture_dir,
                                                           const std::string& out_path,
                                                           const LightfieldEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader input,
                        capture::CaptureSetReader::open(capture_dir, options.max_image_pixels));
  CALF_RETURN_IF_ERROR(files::check_output_not_input(out_path, capture_inputs(input)));
  LightfieldAnalysisFile file;
  file.path = out_path;
  CALF_ASSIGN_OR_RETURN(file.analysis, analyse_lightfield(input, options));
  file.options = options;
  file.clip_metadata = clip_metadata(input.manifest());
  CALF_ASSIGN_OR_RETURN(file.pixels, capture_pixels(input, options));
  const std::string record = analysis_record(file.analysis, options, file.pixels);
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> header,
                        container::encode_track_header(file.analysis.header));
  file.id = id_of(record, header);
  CALF_ASSIGN_OR_RETURN(container::Writer writer, container::Writer::create(out_path));
  CALF_RETURN_IF_ERROR(writer.add_track(file.analysis.header).status());
  CALF_RETURN_IF_ERROR(writer.set_metadata(kAnalysisKey, record));
  CALF_RETURN_IF_ERROR(writer.set_metadata(kAnalysisIdKey, file.id));
  for (const auto& [k, v] : file.clip_metadata) {
    CALF_RETURN_IF_ERROR(writer.set_metadata(kClipMetadataPrefix + k, v));
  }
  CALF_RETURN_IF_ERROR(writer.finish());
  return file;
}

Expected<LightfieldAnalysisFile> read_lightfield_analysis(const std::string& path) {
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(path));
  const std::string* record = reader.find_metadata(kAnalysisKey);
  const std::string* id = reader.find_metadata(kAnalysisIdKey);
  if (!record || !id || reader.tracks().size() != 1 || !reader.chunks().empty() ||
      reader.find_metadata(kShardViewsKey) != nullptr) {
    return bad_record(path, "expected one track, no chunks and the analysis record");
  }
  const auto* header = std::get_if<container::LightfieldTrackHeader>(&reader.tracks()[0].header);
  if (!header) return bad_record(path, "its track is not a lightfield track");
  LightfieldAnalysisFile file;
  file.path = path;
  uint64_t resolved = 0;
  bool coverage_stream = false;
  std::vector<LightfieldViewFacts> facts;
  CALF_RETURN_IF_ERROR(parse_record(path, *record, &file.options, &resolved, &coverage_stream,
                                    &facts, &file.pixels));
  if (Status s = lightfield_internal::validate_options(file.options); !s.ok()) {
    return bad_record(path, s.message());
  }
  // The manifest is not in the file; the facts and header carry all the plan needs.
  LightfieldAnalysis& a = file.analysis;
  a.header = *header;
  a.views = std::move(facts);
  a.colour = static_cast<ColourCoding>(resolved);
  a.hdr = a.colour == ColourCoding::kBc6h || a.colour == ColourCoding::kRgba16f;
  a.coverage = coverage_stream;
  if ((a.coverage && !file.options.coverage) || (file.options.coverage_unmix && !a.coverage)) {
    return bad_record(path, "its coverage stream contradicts its options");
  }
  if (a.views.size() != header->view_count || a.colour == ColourCoding::kAuto ||
      (header->flags & 1) != (a.hdr ? 1 : 0)) {
    return bad_record(path, "the record contradicts the track header");
  }
  const uint32_t segment = pixel_segment(file.options, header->frame_count);
  const uint64_t segments = segment ? (uint64_t{header->frame_count} + segment - 1) / segment : 0;
  for (const auto& hashes : file.pixels) {
    if (hashes.size() != segments) {
      return bad_record(path, "its pixel fingerprints do not cover the clip's segments");
    }
  }
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> header_bytes,
                        container::encode_track_header(a.header));
  file.id = id_of(*record, header_bytes);
  if (file.id != *id) return bad_record(path, "its id does not match its record");
  for (const container::MetadataEntry& e : reader.metadata()) {
    if (e.key.rfind(kClipMetadataPrefix, 0) == 0) {
      file.clip_metadata.emplace_back(e.key.substr(std::string(kClipMetadataPrefix).size()),
                                      e.value);
    }
  }
  return file;
}

Expected<LightfieldEncodeStats> encode_lightfield_shard(
    const std::filesystem::path& capture_dir, const LightfieldAnalysisFile& analysis,
    std::span<const uint32_t> views, uint32_t first_frame, uint32_t frame_count, uint32_t threads,
    const std::string& out_path, uint64_t max_image_pixels) {
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader input,
                        capture::CaptureSetReader::open(capture_dir, max_image_pixels));
  const capture::CaptureManifest& m = input.manifest();
  const container::LightfieldTrackHeader& h = analysis.analysis.header;
  if (m.viewpoints.size() != h.view_count || m.frame_count != h.frame_count ||
      m.face_size != h.face_size) {
    return Status(ErrorId::kShardMismatch,
                  capture_dir.string() + ": this capture set (" +
                      std::to_string(m.viewpoints.size()) + " views, " +
                      std::to_string(m.frame_count) + " frames, face " +
                      std::to_string(m.face_size) + ") is not the one analysed (" +
                      std::to_string(h.view_count) + " views, " + std::to_string(h.frame_count) +
                      " frames, face " + std::to_string(h.face_size) + ")");
  }
  if (views.empty()) return Status(ErrorId::kShardRange, "a shard needs at least one view");
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i] >= h.view_count || (i > 0 && views[i] <= views[i - 1])) {
      return Status(ErrorId::kShardRange, "shard views " + capture::index_list_text(views) +
                                              ": not ascending within the set's " +
                                              std::to_string(h.view_count) + " views");
    }
  }
  if (frame_count == 0 || first_frame >= h.frame_count ||
      frame_count > h.frame_count - first_frame) {
    return Status(ErrorId::kShardRange, "shard frames " + std::to_string(first_frame) + "+" +
                                            std::to_string(frame_count) +
                                            " are outside the set's " +
                                            std::to_string(h.frame_count) + " frames");
  }
  CALF_RETURN_IF_ERROR(
      files::check_output_not_input(out_path, capture_inputs(input, analysis.path)));
  // The images must be the ones analysed, byte for byte: a capture of the same manifest with
  // other pixels would otherwise merge into a mixed clip.
  const uint32_t segment = pixel_segment(analysis.options, h.frame_count);
  // (A range that is not whole segments is refused by the view coder below, E201.)
  const bool whole_segments =
      first_frame % segment == 0 &&
      (frame_count % segment == 0 || first_frame + frame_count == h.frame_count);
  for (const uint32_t v : views) {
    if (v >= analysis.pixels.size() || !whole_segments) break;  // in memory only: none
    for (uint32_t first = first_frame; first < first_frame + frame_count; first += segment) {
      const uint32_t count = std::min(segment, h.frame_count - first);
      CALF_ASSIGN_OR_RETURN(const uint64_t p, pixels_of(input, v, first, count));
      if (p != analysis.pixels[v][first / segment]) {
        return Status(ErrorId::kShardMismatch,
                      capture_dir.string() + ": view " + std::to_string(v) + " frames " +
                          std::to_string(first) + "-" + std::to_string(first + count - 1) +
                          " are not the images analysed (their bytes differ from the ones " +
                          (analysis.path.empty() ? std::string("analysed")
                                                 : "the analysis file " + analysis.path) +
                          " fingerprints)");
      }
    }
  }
  LightfieldEncodeOptions options = analysis.options;
  options.threads = threads;
  CALF_ASSIGN_OR_RETURN(container::Writer writer,
                        container::Writer::create(out_path, options.levels));
  CALF_ASSIGN_OR_RETURN(uint16_t track, writer.add_track(h));
  LightfieldEncodeStats total;
  total.min_colour_quality_db = std::numeric_limits<double>::infinity();
  for (const uint32_t v : views) {
    CALF_ASSIGN_OR_RETURN(const LightfieldViewEncoding enc,
                          encode_lightfield_view_frames(input, analysis.analysis, v, first_frame,
                                                        frame_count, options));
    for (const LightfieldChunk& c : enc.chunks) {
      container::ChunkKeys keys = c.keys;
      keys.track = track;
      CALF_RETURN_IF_ERROR(writer.add_stored_chunk(keys, c.chunk).status());
    }
    total.colour_keyframes += enc.stats.colour_keyframes;
    total.colour_denoised += enc.stats.colour_denoised;
    total.colour_unmixed += enc.stats.colour_unmixed;
    total.colour.stored += enc.stats.colour.stored;
    total.depth.stored += enc.stats.depth.stored;
    total.material.stored += enc.stats.material.stored;
    total.coverage.stored += enc.stats.coverage.stored;
    total.colour_cells += enc.stats.colour_cells;
    total.depth_regions += enc.stats.depth_regions;
    total.min_colour_quality_db =
        std::min(total.min_colour_quality_db, enc.stats.min_colour_quality_db);
  }
  CALF_RETURN_IF_ERROR(writer.set_metadata(kAnalysisIdKey, analysis.id));
  CALF_RETURN_IF_ERROR(writer.set_metadata(kShardViewsKey, capture::index_list_text(views)));
  CALF_RETURN_IF_ERROR(writer.set_metadata(
      kShardFramesKey,
      std::to_string(first_frame) + "-" + std::to_string(first_frame + frame_count - 1)));
  CALF_RETURN_IF_ERROR(writer.finish());
  return total;
}

Status merge_lightfield_shards(const LightfieldAnalysisFile& analysis,
                               std::span<const std::string> shard_paths,
                               const std::string& out_path) {
  const container::LightfieldTrackHeader& h = analysis.analysis.header;
  std::vector<std::string> inputs(shard_paths.begin(), shard_paths.end());
  if (!analysis.path.empty()) inputs.push_back(analysis.path);
  CALF_RETURN_IF_ERROR(files::check_output_not_input(out_path, inputs));
  // Open every shard and check it before anything is written.
  struct Piece {
    uint32_t first, last;  // frames, inclusive
    size_t shard;
  };
  std::vector<container::Reader> readers;
  std::vector<std::vector<Piece>> pieces(h.view_count);  // per view, the shards holding it
  for (size_t i = 0; i < shard_paths.size(); ++i) {
    const std::string& path = shard_paths[i];
    CALF_ASSIGN_OR_RETURN(container::Reader r, container::Reader::open(path));
    const std::string* id = r.find_metadata(kAnalysisIdKey);
    const std::string* views_text = r.find_metadata(kShardViewsKey);
    const std::string* frames_text = r.find_metadata(kShardFramesKey);
    if (!id || !views_text || !frames_text || r.tracks().size() != 1) {
      return Status(ErrorId::kShardFile, path + ": not a calf shard file (no shard record)");
    }
    if (*id != analysis.id) {
      return Status(ErrorId::kShardMismatch, path + ": coded with analysis " + *id +
                                                 ", not with the given analysis " + analysis.id);
    }
    Expected<std::vector<uint32_t>> views =
        capture::parse_index_list(*views_text, h.view_count, "views");
    Expected<std::vector<uint32_t>> frames =
        capture::parse_index_list(*frames_text, h.frame_count, "frames");
    if (!views.ok() || !frames.ok() || frames->back() - frames->front() + 1 != frames->size()) {
      return Status(ErrorId::kShardFile, path + ": bad shard record (views '" + *views_text +
                                             "', frames '" + *frames_text + "')");
    }
    for (const uint32_t v : *views) pieces[v].push_back({frames->front(), frames->back(), i});
    for (const container::ChunkEntry& c : r.chunks()) {
      const bool listed = c.keys.view < h.view_count &&
                          std::binary_search(views->begin(), views->end(), c.keys.view);
      if (c.keys.track != 0 || !listed) {
        return Status(ErrorId::kShardFile, path + ": holds a chunk of view " +
                                               std::to_string(c.keys.view) +
                                               " outside its record " + *views_text);
      }
    }
    readers.push_back(std::move(r));
  }
  // Every frame of every view in exactly one shard.
  for (uint32_t v = 0; v < h.view_count; ++v) {
    std::vector<Piece>& p = pieces[v];
    std::sort(p.begin(), p.end(), [](const Piece& a, const Piece& b) { return a.first < b.first; });
    uint32_t next = 0;
    for (const Piece& piece : p) {
      if (piece.first < next) {
        const Piece& other = *std::find_if(p.begin(), p.end(), [&](const Piece& q) {
          return &q != &piece && q.last >= piece.first && q.first <= piece.last;
        });
        return Status(ErrorId::kShardOverlap, shard_paths[piece.shard] + " and " +
                                                  shard_paths[other.shard] + " both hold view " +
                                                  std::to_string(v) + ", frame " +
                                                  std::to_string(piece.first));
      }
      if (piece.first > next) break;
      next = piece.last + 1;
    }
    if (next < h.frame_count) {
      return Status(ErrorId::kShardMissing,
                    "view " + std::to_string(v) + " of " + std::to_string(h.view_count) +
                        ", frame " + std::to_string(next) + " of " + std::to_string(h.frame_count) +
                        " is in none of the " + std::to_string(shard_paths.size()) + " shards");
    }
  }
  // The clip: the same calls, in the same order, as encode_lightfield_file() makes. A view's
  // chunks from its shards go in the encoder's file order (index; per face: colour cells with
  // their t chunk then keyframes, depth regions, material tiles; each by frame); the partial t
  // chunks of one cell are joined and compressed as one encode does.
  CALF_ASSIGN_OR_RETURN(container::Writer writer,
                        container::Writer::create(out_path, analysis.options.levels));
  CALF_ASSIGN_OR_RETURN(uint16_t track, writer.add_track(h));
  using container::LightfieldStream;
  auto stream_class = [](uint16_t stream) {
    switch (static_cast<LightfieldStream>(stream)) {
      case LightfieldStream::kIndex:
        return 0;
      case LightfieldStream::kTParams:
        return 1;
      case LightfieldStream::kColour:
        return 2;
      case LightfieldStream::kDepth:
        return 3;
      case LightfieldStream::kMaterial:
        return 4;
      default:
        return 5;
    }
  };
  struct Ref {
    size_t shard;
    uint32_t id;
    container::ChunkKeys keys;
  };
  for (uint32_t v = 0; v < h.view_count; ++v) {
    std::vector<Ref> refs;
    for (const Piece& piece : pieces[v]) {
      const container::Reader& r = readers[piece.shard];
      container::ChunkQuery q;
      q.view = v;
      for (const uint32_t id : r.find_chunks(q)) {
        refs.push_back({piece.shard, id, r.chunks()[id].keys});
      }
    }
    auto order = [&](const Ref& r) {
      const int c = stream_class(r.keys.stream);
      // Colour cells (t and keyframes together), then depth, material and coverage tiles.
      const int group = c == 0 ? 0 : c <= 2 ? 1 : c;
      return std::tuple(c == 0 ? 0 : 1, r.keys.face, group, r.keys.region, c, r.keys.first_frame);
    };
    std::stable_sort(refs.begin(), refs.end(),
                     [&](const Ref& a, const Ref& b) { return order(a) < order(b); });
    for (size_t i = 0; i < refs.size();) {
      const Ref& ref = refs[i];
      if (ref.keys.stream == static_cast<uint16_t>(LightfieldStream::kCoverage)) {
        writer.require_minor_version(container::kVersionMinorCoverage);
      }
      const container::Reader& r = readers[ref.shard];
      const container::ChunkEntry& e = r.chunks()[ref.id];
      container::ChunkKeys keys = e.keys;
      keys.track = track;
      container::StoredChunk chunk;
      const bool partial_t = keys.stream == static_cast<uint16_t>(LightfieldStream::kTParams) &&
                             keys.frame_count != h.frame_count;
      if (!partial_t) {
        chunk.compression = static_cast<container::Compression>(e.compression);
        chunk.raw_size = e.raw_size;
        CALF_ASSIGN_OR_RETURN(chunk.bytes, r.read_stored(ref.id));
        CALF_RETURN_IF_ERROR(writer.add_stored_chunk(keys, chunk).status());
        ++i;
        continue;
      }
      // The cell's t chunks of every segment range, in frame order.
      std::vector<std::vector<uint8_t>> parts;
      std::vector<uint32_t> counts;
      size_t j = i;
      for (; j < refs.size() && order(refs[j]) < std::tuple(1, keys.face, 1, keys.region, 2, 0u);
           ++j) {
        CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw,
                              readers[refs[j].shard].read_chunk(refs[j].id));
        parts.push_back(std::move(raw));
        counts.push_back(refs[j].keys.frame_count);
      }
      CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> joined, join_t_chunks(parts, counts));
      CALF_ASSIGN_OR_RETURN(chunk,
                            container::compress_chunk(joined, analysis.options.supercompression,
                                                      analysis.options.levels));
      keys.first_frame = 0;
      keys.frame_count = h.frame_count;
      CALF_RETURN_IF_ERROR(writer.add_stored_chunk(keys, chunk).status());
      i = j;
    }
  }
  for (const auto& [k, value] : analysis.clip_metadata) {
    CALF_RETURN_IF_ERROR(writer.set_metadata(k, value));
  }
  return writer.finish();
}

}  // namespace calf::encoder
