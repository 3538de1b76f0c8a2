// Pass 1 of the light-field encoder: every decision global to the track, made from the whole
// capture set before any view is coded (see lightfield_encode.h "Two passes").
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/colour_denoise.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/av1_hdr_colour.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "lightfield_internal.h"

namespace calf::encoder {
namespace lightfield_internal {

Status validate_options(const LightfieldEncodeOptions& o) {
  auto bad = [](const std::string& what) { return Status(ErrorId::kEncoderOption, what); };
  if (o.cell_size < 4 || o.cell_size > kMaxFaceSize || o.cell_size % 4 != 0) {
    return bad("--cell " + std::to_string(o.cell_size) +
               ": expected a multiple of 4 in [4, 16384]");
  }
  if (!(o.min_psnr_db > 0 && o.min_psnr_db <= 200)) {
    return bad("--psnr " + std::to_string(o.min_psnr_db) + ": expected (0, 200] dB");
  }
  if (!(o.noise_psnr_db == 0 || (o.noise_psnr_db > 0 && o.noise_psnr_db <= 300))) {
    return bad("noise level " + std::to_string(o.noise_psnr_db) + ": expected 0 or (0, 300] dB");
  }
  if (!(o.noise_factor >= 0 && o.noise_factor <= 16)) {
    return bad("--psnr-noise-factor " + std::to_string(o.noise_factor) + ": expected [0, 16]");
  }
  if (o.denoise_window > kMaxDenoiseWindow) {
    return bad("--denoise-window " + std::to_string(o.denoise_window) + ": expected [0, " +
               std::to_string(kMaxDenoiseWindow) + "]");
  }
  if (o.coverage_unmix) {
    const capture::CoverageUnmixOptions& u = *o.coverage_unmix;
    if (!(u.min_share >= 0 && u.min_share <= 1)) {
      return bad("--coverage-unmix " + std::to_string(u.min_share) + ": expected [0, 1]");
    }
    if (!(u.min_jump >= 0 && u.min_jump <= 1e6)) {
      return bad("--coverage-unmix-jump " + std::to_string(u.min_jump) + ": expected [0, 1e6]");
    }
  }
  if (o.depth_regions_per_side < 1 || o.depth_regions_per_side > 64) {
    return bad("depth regions per side " + std::to_string(o.depth_regions_per_side) +
               ": expected [1, 64]");
  }
  if (o.depth_window < 1 || o.depth_window > 65535) {
    return bad("--depth-window " + std::to_string(o.depth_window) + ": expected [1, 65535]");
  }
  if (o.max_aabbs < 1 || o.max_aabbs > 64) {
    return bad("--max-aabbs " + std::to_string(o.max_aabbs) + ": expected [1, 64]");
  }
  if (o.depth_keyframe_interval < 1) {
    return bad("--depth-keyframe-interval 0: expected >= 1");
  }
  if (o.segment_frames != 0 && o.segment_frames % o.depth_keyframe_interval != 0) {
    return bad("--segment-frames " + std::to_string(o.segment_frames) +
               ": expected a multiple of --depth-keyframe-interval " +
               std::to_string(o.depth_keyframe_interval) + " (or 0, no segments)");
  }
  if (o.colour_rdo != kColourRdoAuto && !(o.colour_rdo >= 0 && o.colour_rdo <= 1e6)) {
    return bad("--colour-rdo " + std::to_string(o.colour_rdo) + ": expected [0, 1e6] or auto");
  }
  if (static_cast<uint8_t>(o.bc1_fit) > static_cast<uint8_t>(Bc1Fit::kCluster)) {
    return bad("unknown BC1 fit");
  }
  if (o.colour == ColourCoding::kAv1) {
    const Av1ColourOptions& a = o.av1;
    if (a.crf < 1 || a.crf > 63)
      return bad("--av1-crf " + std::to_string(a.crf) + ": expected [1, 63]");
    if (a.qp > 63) return bad("--av1-qp " + std::to_string(a.qp) + ": expected [1, 63]");
    if (a.preset > (a.chroma444 ? 9u : 13u)) {
      return bad("--av1-preset " + std::to_string(a.preset) +
                 (a.chroma444 ? ": expected [0, 9] (libaom cpu-used, --av1-chroma 444)"
                              : ": expected [0, 13]"));
    }
    if (a.keyframe_interval < 1) return bad("--av1-keyframe-interval 0: expected >= 1");
    if (o.segment_frames != 0) return bad("--segment-frames with AV1 colour: not supported");
  }
  // 256 as calf-capture's: beyond it oneTBB prints warnings of its own (a library never prints).
  if (o.threads > 256) return bad("--threads " + std::to_string(o.threads) + ": expected [0, 256]");
  if (static_cast<uint16_t>(o.supercompression) >= container::kCompressionCount) {
    return bad("unknown supercompression");
  }
  return Status::Ok();
}

Status read_frame(const capture::CaptureSetReader& input, uint32_t view, uint32_t frame,
                  capture::ViewFrame* out) {
  const capture::CaptureManifest& m = input.manifest();
  CALF_RETURN_IF_ERROR(input.read(view, frame, out));
  if (out->face_size != m.face_size || out->has_material != m.material) {
    return Status(ErrorId::kEncoderInput, input.image_path(view, frame).string() +
                                              ": face size or material differs from the manifest");
  }
  return Status::Ok();
}

void ViewFactsBuilder::add(const capture::ViewFrame& frame) {
  for (const float z : frame.depth) {
    if (std::isfinite(z)) {
      lo_ = std::min(lo_, z);
      hi_ = std::max(hi_, z);
    }
  }
  // Material counts as present where a weight survives its 8-bit code: what the decoder sees.
  for (size_t i = 0; !has_material_ && i + 2 < frame.material.size(); i += 3) {
    has_material_ = lf::material_weight_code(frame.material[i]) != 0 ||
                    lf::material_weight_code(frame.material[i + 1]) != 0;
  }
  if (!hdr_)
    hdr_ = std::any_of(frame.color.begin(), frame.color.end(), [](float c) { return c > 1.0f; });
}

Expected<LightfieldViewFacts> ViewFactsBuilder::finish() const {
  LightfieldViewFacts facts;
  facts.has_material = has_material_;
  facts.hdr = hdr_;
  if (hi_ > 0) {  // some finite depth (capture depths are > 0): else the view sees only sky
    CALF_ASSIGN_OR_RETURN(LogDepthRange r, LogDepthRange::covering(lo_, hi_));
    facts.depth_range = r;
  }
  return facts;
}

bool ViewFactsBuilder::within(const LightfieldViewFacts& whole) const {
  if ((has_material_ && !whole.has_material) || (hdr_ && !whole.hdr)) return false;
  if (hi_ == 0) return true;  // only sky in these frames
  return whole.depth_range && lo_ >= whole.depth_range->z_near() &&
         hi_ <= whole.depth_range->z_far();
}

bool same_facts(const LightfieldViewFacts& a, const LightfieldViewFacts& b) {
  if (a.has_material != b.has_material || a.hdr != b.hdr) return false;
  if (a.depth_range.has_value() != b.depth_range.has_value()) return false;
  return !a.depth_range || (a.depth_range->z_near() == b.depth_range->z_near() &&
                            a.depth_range->z_far() == b.depth_range->z_far());
}

}  // namespace lightfield_internal

namespace {

uint16_t pf(container::PixelFormat f) {
  return static_cast<uint16_t>(f);
}

// The track's frame rate as a reduced fraction with a millihertz resolution.
std::pair<uint32_t, uint32_t> fps_rational(double fps) {
  uint64_t num = static_cast<uint64_t>(std::llround(fps * 1000.0));
  uint64_t den = 1000;
  if (num == 0) num = 1;
  const uint64_t g = std::gcd(num, den);
  num /= g;
  den /= g;
  num = std::min<uint64_t>(num, UINT32_MAX);
  return {static_cast<uint32_t>(num), static_cast<uint32_t>(den)};
}

}  // namespace

Expected<LightfieldViewFacts> analyse_lightfield_view(const capture::CaptureSetReader& input,
                                                      uint32_t view) {
  lightfield_internal::ViewFactsBuilder facts;
  capture::ViewFrame vf;
  for (uint32_t f = 0; f < input.manifest().frame_count; ++f) {
    CALF_RETURN_IF_ERROR(lightfield_internal::read_frame(input, view, f, &vf));
    facts.add(vf);
  }
  return facts.finish();
}

Expected<LightfieldAnalysis> plan_lightfield(const capture::CaptureManifest& m,
                                             std::span<const LightfieldViewFacts> views,
                                             const LightfieldEncodeOptions& options) {
  using container::PixelFormat;
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  if (views.size() != m.viewpoints.size()) {
    return Status(ErrorId::kEncoderInput, "facts of " + std::to_string(views.size()) +
                                              " views for a capture set of " +
                                              std::to_string(m.viewpoints.size()));
  }
  CALF_ASSIGN_OR_RETURN(FaceGrid cells, FaceGrid::with_cell_size(m.face_size, options.cell_size));
  CALF_ASSIGN_OR_RETURN(
      FaceGrid tiles, FaceGrid::with_regions_per_side(m.face_size, options.depth_regions_per_side));
  LightfieldAnalysis a;
  a.views.assign(views.begin(), views.end());
  // HDR or LDR: decided over the whole set unless the format is given. LDR input never pays for
  // a HDR format.
  a.colour = options.colour;
  if (a.colour == ColourCoding::kAuto) {
    const bool hdr = std::any_of(views.begin(), views.end(), [](const auto& v) { return v.hdr; });
    a.colour = hdr ? ColourCoding::kBc6h : ColourCoding::kBc1;
  }
  // AV1 colour of a set with HDR colour is the HDR AV1 format (10-bit codes of half floats).
  const bool av1_hdr = a.colour == ColourCoding::kAv1 &&
                       std::any_of(views.begin(), views.end(), [](const auto& v) { return v.hdr; });
  a.hdr = a.colour == ColourCoding::kBc6h || a.colour == ColourCoding::kRgba16f || av1_hdr;
  container::LightfieldTrackHeader& h = a.header;
  switch (a.colour) {
    case ColourCoding::kBc1:
      h.colour_format = pf(PixelFormat::kBc1);
      break;
    case ColourCoding::kBc7:
      h.colour_format = pf(PixelFormat::kBc7);
      break;
    case ColourCoding::kBc6h:
      h.colour_format = pf(PixelFormat::kBc6h);
      break;
    case ColourCoding::kRgba8:
      h.colour_format = pf(PixelFormat::kRgba8);
      break;
    case ColourCoding::kAv1:
      if (options.av1.chroma444) {
        h.colour_format = pf(av1_hdr ? PixelFormat::kAv1HdrChroma444 : PixelFormat::kAv1Chroma444);
      } else {
        h.colour_format = pf(av1_hdr ? PixelFormat::kAv1Hdr : PixelFormat::kAv1);
      }
      break;
    default:
      h.colour_format = pf(PixelFormat::kRgba16f);
      break;
  }
  const bool lossy_depth = options.depth == DepthCoding::kBc5;
  h.depth_format =
      pf(lossy_depth                                           ? PixelFormat::kBc5
         : options.depth == DepthCoding::kRaw16Predicted       ? PixelFormat::kR16Predicted
         : options.depth == DepthCoding::kRaw16PredictedMasked ? PixelFormat::kR16PredictedMasked
                                                               : PixelFormat::kR16);
  // Material is coded like depth: raw bytes beside raw depth, BC1 beside BC5.
  const bool material =
      std::any_of(views.begin(), views.end(), [](const auto& v) { return v.has_material; });
  h.material_format = material ? pf(lossy_depth ? PixelFormat::kBc1 : PixelFormat::kRgba8) : 0;
  h.frame_count = m.frame_count;
  std::tie(h.fps_numerator, h.fps_denominator) = fps_rational(m.fps);
  h.view_count = static_cast<uint32_t>(m.viewpoints.size());
  h.face_size = m.face_size;
  h.cell_size = cells.cell_size();
  h.depth_region_size = tiles.cell_size();
  h.flags = a.hdr ? 1 : 0;
  a.coverage = m.coverage && options.coverage;
  return a;
}

Expected<LightfieldAnalysis> analyse_lightfield(const capture::CaptureSetReader& input,
                                                const LightfieldEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  const capture::CaptureManifest& m = input.manifest();
  if (options.coverage_unmix && !(m.coverage && options.coverage)) {
    return Status(ErrorId::kEncoderInput,
                  m.coverage ? "unmixing needs the coverage stream, which the options drop"
                             : "unmixing needs coverage, and the capture set has none "
                               "(format/CAPTURE.md \"Coverage\")");
  }
  CALF_RETURN_IF_ERROR(input.check_files());
  // The grids first: a bad cell size fails before any image is read.
  CALF_RETURN_IF_ERROR(FaceGrid::with_cell_size(m.face_size, options.cell_size).status());
  CALF_RETURN_IF_ERROR(
      FaceGrid::with_regions_per_side(m.face_size, options.depth_regions_per_side).status());

  // Views are read in parallel; the error reported is the first failing view's, as a serial
  // read would report it. Views after a known failure are skipped.
  const uint32_t n = static_cast<uint32_t>(m.viewpoints.size());
  std::vector<LightfieldViewFacts> facts(n);
  std::vector<Status> status(n);
  std::atomic<uint32_t> first_failure{n};
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, n, 1),
                      [&](const tbb::blocked_range<uint32_t>& range) {
                        for (uint32_t v = range.begin(); v < range.end(); ++v) {
                          if (v > first_failure.load()) continue;
                          Expected<LightfieldViewFacts> f = analyse_lightfield_view(input, v);
                          if (f.ok()) {
                            facts[v] = std::move(*f);
                            continue;
                          }
                          status[v] = f.status();
                          uint32_t seen = first_failure.load();
                          while (v < seen && !first_failure.compare_exchange_weak(seen, v)) {
                          }
                        }
                      });
  });
  if (first_failure.load() < n) return status[first_failure.load()];
  return plan_lightfield(m, facts, options);
}

}  // namespace calf::encoder
