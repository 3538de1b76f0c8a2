// The light-field track encoder (paper 002, Sec. 5): a capture set in, a lightfield track of a
// .calf container out, laid out as format/SPEC.md §11.1 specifies.
//
//   colour    per view, face and cell (default 64 x 64): keyframes chosen by Alg. 2
//             (calf/encoder/colour_keyframes.h), each stored as one chunk in the colour format
//             (BC1 for LDR input, BC6H for HDR input, or BC7 / raw RGBA8 / raw RGBA16F), plus one
//             chunk of 8-bit interpolation weights t per cell.
//   depth     per view a log-16 range measured from the data (z_near / z_far over every finite
//             depth of every frame); per face tile (default 2 x 2 per face) one chunk per
//             keyframe interval holding a keyframe and P-frames of at most A rectangles covering
//             the texels that differ from any of the previous W frames (Alg. 3,
//             calf/encoder/depth_aabb.h); raw 16-bit (exact) or BC5 (hi / lo byte, lossy).
//   material  only for views that see a reflective or refractive texel: coded like depth, as
//             raw bytes when depth is raw16 and as BC1 when depth is BC5.
//
// Quality (what Q means). Q bounds the *temporal* loss: every frame x of every cell, as the
// decoder shows it (keyframes after BCn decode, t quantised to 8 bits, interpolated in linear
// light), is within Q dB of frame x as the spatial codec alone would show it (x encoded as if it
// were a keyframe). The spatial codec's own loss is the chosen format's (BC1 ~35-45 dB); measuring
// the interpolation against the original instead would make every frame a keyframe whenever the
// format's own PSNR is below Q, and a static cell would never be one keyframe. LDR cells use
// PSNR on sRGB (psnr_srgb); HDR cells use log2-PSNR (psnr_log2 below).
//
// Two passes. Encoding is split so that the views of one clip can be coded apart (threads,
// processes or machines) and merged into the very bytes a single run writes:
//
//   1. analysis   analyse_lightfield() reads every image once and decides everything global —
//                 HDR or LDR colour, each view's depth range and material presence, whether the
//                 track has a material stream — into a LightfieldAnalysis holding the final track
//                 header. Where the images are spread out, run analyse_lightfield_view() beside
//                 each view's images and combine the facts with plan_lightfield().
//   2. views      encode_lightfield_view() codes one view into its chunks, a pure function of the
//                 analysis, that view's images and the options; views are independent.
//   3. assembly   LightfieldTrackWriter adds the track with the analysis's header and appends the
//                 views' chunks in view order. No header field is patched afterwards.
//
// encode_lightfield() runs the three steps in one process, one view at a time. Every image is
// read twice, once per pass (measured: 5-9 % more CPU time on a 128-texel, 8-frame, 9-view set).
//
// Determinism: the output bytes depend on the input and the options only, never on `threads` nor
// on where or in which order the views were coded (cells and tiles are coded independently into
// per-task buffers, then appended in a fixed order).
// Memory: encode_lightfield() holds one view at a time (all its frames: ~13 bytes per texel per
// frame, plus that view's compressed chunks), never all views; the analysis holds one frame per
// thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/coverage_unmix.h"
#include "calf/format/container.h"
#include "calf/format/log_depth.h"
#include "calf/format/status.h"

namespace calf::encoder {

// Colour format choice; kAuto = BC1 for LDR input (every colour value <= 1), BC6H for HDR.
// kAv1: per cell one AV1 stream (SPEC §11.1.12): 8-bit sRGB pictures for LDR input, 10-bit codes
// of half floats (format av1hdr) for HDR input; 4:2:0 by SVT-AV1 or 4:4:4 by libaom
// (Av1ColourOptions::chroma444, formats av1-444 and av1hdr-444).
enum class ColourCoding : uint8_t { kAuto, kBc1, kBc7, kBc6h, kRgba8, kRgba16f, kAv1 };

// AV1 colour (ColourCoding::kAv1): the AV1 encoder's settings. Each cell's frames are coded as
// closed GOPs of `keyframe_interval` frames, one fresh single-threaded encoder each, so the bytes
// never depend on LightfieldEncodeOptions::threads.
struct Av1ColourOptions {
  uint32_t crf = 32;    // constant rate factor 1..63 (lower: better and larger); libaom: cq-level
  uint32_t qp = 0;      // 1..63: a fixed quantiser instead of the CRF; 0 = CRF
  uint32_t preset = 5;  // SVT-AV1 preset 0..13, or with chroma444 libaom cpu-used 0..9 (higher:
                        // faster, larger)
  uint32_t keyframe_interval = 30;  // K >= 1: a key frame every K frames, the seek granularity
  // false: 4:2:0 pictures by SVT-AV1 (formats av1, av1hdr; the Main profile every decoder plays);
  // true: 4:4:4 pictures by libaom (formats av1-444, av1hdr-444; the High profile, container
  // 1.5), which keep the per-texel colour 4:2:0 averages away (docs/ENCODER.md "AV1 colour").
  bool chroma444 = false;
};
// kRaw16: log-16 codes as 16-bit planes (SPEC §11.1.6); kRaw16Predicted: the same codes as
// spatial-prediction residuals (depth format r16p, SPEC §11.1.8), lossless like kRaw16 and
// smaller once supercompressed; kBc5: lossy; kRaw16PredictedMasked: as kRaw16Predicted, but a
// P-frame rectangle stores a change mask and the residuals of its changed texels only (depth
// format r16pm, SPEC §11.1.9). Values are recorded in analysis files: append only.
enum class DepthCoding : uint8_t { kRaw16, kBc5, kRaw16Predicted, kRaw16PredictedMasked };
// How BC1 colour blocks are fitted (calf/encoder/bc_encode.h): kRange = libsquish's range fit
// (the fastest), kRefined = range fit plus least-squares endpoint refinement
// (Bc1Options::refine), kCluster = libsquish's cluster fit. Costs and gains: docs/ENCODER.md
// "BC1 fit". Values are recorded in analysis files: append only.
enum class Bc1Fit : uint8_t { kRange, kRefined, kCluster };
// LightfieldEncodeOptions::colour_rdo's "auto": the measured default of each colour format
// (colour_rdo_lambda).
inline constexpr double kColourRdoAuto = -1;
// kColourRdoAuto's lambda for BC6H colour of a capture measured noisy (noise_psnr_db > 0) with the
// pre-filter on (denoise_window > 1): what is left of the noise costs BC6H blocks their
// neighbours' bytes, and the filter's gain against the converged render pays for it
// (docs/ENCODER.md "Keyframes and render noise").
inline constexpr double kDenoisedBc6hRdo = 2;
// LightfieldEncodeOptions::noise_factor's default (docs/ENCODER.md "Keyframes and render noise").
inline constexpr double kDefaultNoiseFactor = 3;

struct LightfieldEncodeOptions {
  uint32_t cell_size = 64;  // colour cell side (px), 4..16384 and a multiple of 4
  double min_psnr_db = 50;  // Q, (0, 200]
  // The noise-aware keyframe test (KeyframeOptions::noise, docs/ENCODER.md "Keyframes and render
  // noise"), set by calf-encode --psnr auto when the estimate sets Q below 50: the capture's
  // render-noise estimate as PSNR in the colour test's metric, 0 = off (the plain test), else
  // (0, 300]; and the factor on each block's measured noise (the part not charged for), [0, 16].
  double noise_psnr_db = 0;
  double noise_factor = kDefaultNoiseFactor;
  // The temporal pre-filter of render noise on static geometry (calf/encoder/colour_denoise.h):
  // before any colour coding, each view's texels whose geometry stays put are averaged over a
  // window of this many frames where the change is one the noise explains; 0 or 1 = off (the
  // default here; calf-encode turns it on with --psnr auto's noise-aware test), at most 64.
  // Each block's noise counts at most 8 times noise_psnr_db's when that is set.
  uint32_t denoise_window = 0;
  ColourCoding colour = ColourCoding::kAuto;
  // The smallest lossless depth; its decode cost against raw16: docs/DECODER.md.
  DepthCoding depth = DepthCoding::kRaw16PredictedMasked;
  uint32_t depth_regions_per_side = 2;    // 1..64
  uint32_t depth_window = 2;              // W, >= 1
  uint32_t max_aabbs = 2;                 // A, 1..64
  uint32_t depth_keyframe_interval = 30;  // a depth keyframe every K frames, >= 1
  // Closed colour segments (like a video encoder's closed GOP): 0 = none; else the colour
  // keyframe search of every cell restarts every N frames (frame N, 2N, ... is a keyframe), so
  // that frame ranges of whole segments code apart into the very bytes of one encode
  // (lightfield_shard.h). A multiple of depth_keyframe_interval, so depth groups never straddle
  // a segment. Costs bytes (docs/FARM.md).
  uint32_t segment_frames = 0;
  // A depth / material tile that does not change over whole groups of K frames after its group
  // keeps one chunk across them (empty P-frames there, but for the first W - 1) instead of a new
  // keyframe every K frames: static content costs one keyframe per tile, and a seek still reads
  // one chunk of it (SPEC §11.1.2 "Static groups"). Groups never merge across a segment
  // boundary. false: one chunk per K frames (the layout without static groups).
  bool merge_static_groups = true;
  // Code the capture set's coverage (format/CAPTURE.md "Coverage") as the track's coverage stream
  // (SPEC §11.1.11) when the set has it; false drops it. A set without coverage is coded the same
  // either way.
  bool coverage = true;
  // Unmixed colour at depth edges, baked into the clip (calf/capture/coverage_unmix.h): before any
  // colour coding, each frame of each view with coverage solves its edge texels for their own
  // surface's colour, as the CPU reference's unmixing does with the decoded coverage (shares in
  // 16ths). Absent (the default): the colour is coded as captured. Needs a coverage stream
  // (a capture set with coverage and `coverage` true). docs/SILHOUETTES.md "Unmixed colour at
  // sky edges" measures {0.25, 1000}: sky edges only.
  std::optional<capture::CoverageUnmixOptions> coverage_unmix;
  // Colour RDO strength (calf/encoder/bc_rdo.h): lambda, squared 8-bit sRGB error per estimated
  // bit saved, [0, 1e6]; 0 = off (the blocks as the BCn encoder made them). BC1, BC6H and BC7
  // keyframes; rgba8 / rgba16f ignore it. Applied to the keyframes after the
  // keyframe search. kColourRdoAuto (the default): 0.5 for BC6H / BC7, 12 for BC1, each chosen
  // by measurement (docs/ENCODER.md "Colour RDO", "BC1 fit"), and kDenoisedBc6hRdo for BC6H of a
  // noisy capture with the pre-filter on; see colour_rdo_lambda.
  double colour_rdo = kColourRdoAuto;
  // BC1 colour only: the block fit (above). Cluster fit by default: with the BC1
  // RDO at its default it is what keeps LDR content within 0.05 dB of --colour-rdo 0
  // while saving 30 % of its colour bytes.
  Bc1Fit bc1_fit = Bc1Fit::kCluster;
  // ColourCoding::kAv1 only.
  Av1ColourOptions av1;
  container::Compression supercompression = container::Compression::kZstd;
  container::CompressionOptions levels;  // zstd level / LZMA preset (fixed per clip)
  uint32_t threads = 1;                  // 0 = all cores; never changes the output
  // The image budget of the capture set read (CaptureSetReader::open): 6 face_size^2 pixels per
  // view-frame at most, else E012 before any frame is read. Never changes the output.
  uint64_t max_image_pixels = capture::kDefaultMaxImagePixels;
  // Called after each view-face is coded (done, total), by encode_lightfield_view() on the
  // calling thread only; the analysis pass does not report.
  std::function<void(uint64_t done, uint64_t total)> progress;
};

// Bytes of one stream at each stage of paper 002 Table 1.
struct StreamBytes {
  uint64_t raw = 0;       // every frame uncompressed (colour: RGBA8 or RGBA16F; depth: 16-bit;
                          // material: 3 bytes per texel)
  uint64_t temporal = 0;  // after temporal coding, payload in the raw format (+ t, rect tables)
  uint64_t spatial = 0;   // after spatial (BCn) coding too: the chunks' raw bytes
  uint64_t stored = 0;    // after supercompression: the chunks' stored bytes
  uint64_t chunks = 0;
};

struct LightfieldEncodeStats {
  uint16_t colour_format = 0, depth_format = 0, material_format = 0;  // container::PixelFormat
  bool hdr = false;
  StreamBytes colour;  // keyframe chunks and t chunks together
  StreamBytes depth;
  StreamBytes material;
  StreamBytes coverage;      // raw: 3 bytes per texel (mask, near count)
  uint64_t index_bytes = 0;  // stored bytes of the per-view index chunks
  uint64_t colour_cells = 0, colour_keyframes = 0;
  uint64_t depth_regions = 0, depth_keyframes = 0, depth_pframes = 0, depth_empty_pframes = 0;
  uint64_t material_views = 0;
  double min_colour_quality_db = 0;  // lowest temporal quality of any frame of any cell (+inf)
  // denoise_window > 1: texel-frames whose colour the pre-filter replaced by a temporal mean.
  uint64_t colour_denoised = 0;
  // coverage_unmix: texel-frames whose colour unmixing changed.
  uint64_t colour_unmixed = 0;
  // BC5 depth only: reconstruction error against the quantised input over every finite texel of
  // every frame, as relative depth error |z' / z - 1|, and texels whose sky-ness changed.
  double depth_max_rel_error = 0, depth_mean_rel_error = 0;
  uint64_t depth_sky_mismatches = 0;
  // The terms of the mean (sum of |z' / z - 1| over that many texels), kept so that the figures
  // of views coded apart merge exactly as LightfieldTrackWriter does.
  double depth_sum_rel_error = 0;
  uint64_t depth_finite_texels = 0;
};

// ---- Pass 1: analysis ----

// What the images of one view say, for the decisions global to the track.
struct LightfieldViewFacts {
  // The log-16 range covering every finite depth of every frame (LogDepthRange::covering); none
  // when the view sees only sky. Written in the view's index chunk (z_near, z_far, has_depth).
  std::optional<LogDepthRange> depth_range;
  // Some texel of some frame reflects or refracts (a non-zero 8-bit weight code): the view has
  // material chunks, and the track a material stream.
  bool has_material = false;
  // Some colour value of some frame exceeds 1: the view asks for a HDR colour format.
  bool hdr = false;
};

// Everything global to a lightfield track, decided before any view is coded.
struct LightfieldAnalysis {
  // The final track header: formats, grid sizes, frame and view counts, the HDR flag, and
  // material_format (kNone unless some view has material). Written as is.
  container::LightfieldTrackHeader header;
  // The colour format (never kAuto): options.colour, or for kAuto BC6H when some view is HDR
  // and BC1 otherwise.
  ColourCoding colour = ColourCoding::kBc1;
  bool hdr = false;  // colour is BC6H or RGBA16F (header.flags bit 0)
  // The track has a coverage stream: the set has coverage and options.coverage is on. The file
  // is then container version 1.2 (SPEC §11.1.11).
  bool coverage = false;
  std::vector<LightfieldViewFacts> views;  // one per viewpoint, in manifest order
};

// Reads every frame of view `view` (each validated by the capture reader) and returns its facts.
// Errors: the capture reader's; kEncoderInput for a frame whose face size or material presence
// differs from the manifest; kDepthRange when the measured depths admit no range.
Expected<LightfieldViewFacts> analyse_lightfield_view(const capture::CaptureSetReader& input,
                                                      uint32_t view);

// The analysis from the manifest, every view's facts (manifest order) and the options: a pure
// function, so machines that analysed different views agree on it. Errors: kEncoderOption;
// kEncoderInput (facts not one per viewpoint, a face too small for the grid).
Expected<LightfieldAnalysis> plan_lightfield(const capture::CaptureManifest& manifest,
                                             std::span<const LightfieldViewFacts> views,
                                             const LightfieldEncodeOptions& options);

// Pass 1 in one call: checks the options and that every image exists, analyses every view
// (options.threads views at a time; the first failing view in view order is reported) and plans.
Expected<LightfieldAnalysis> analyse_lightfield(const capture::CaptureSetReader& input,
                                                const LightfieldEncodeOptions& options);

// ---- Pass 2: one view ----

// One chunk of a view, compressed, with its keys; keys.track is left 0 (the assembly sets it).
struct LightfieldChunk {
  container::ChunkKeys keys;
  container::StoredChunk chunk;
};

// The chunks of one view in file order (SPEC §11.1: its index chunk, then per face in GL order
// the colour cells' t and keyframe chunks, the depth regions' chunks, the material tiles' chunks)
// and that view's figures (counts and bytes of this view only; formats and hdr as the track's).
struct LightfieldViewEncoding {
  uint32_t view = 0;
  std::vector<LightfieldChunk> chunks;
  LightfieldEncodeStats stats;
};

// Codes view `view` of `input` as `analysis` decided: reads its frames again, checks that they
// still say what the analysis saw, and codes its cells and tiles (options.threads at a time).
// `options` must be those the analysis was planned with. Calls options.progress after each face
// with (6 * view + face + 1, 6 * view_count). Errors: kEncoderOption; kEncoderInput (view out of
// range, an analysis planned for another capture set or other options, an image that changed
// since the analysis); the capture reader's; container and block-codec errors passed through.
Expected<LightfieldViewEncoding> encode_lightfield_view(const capture::CaptureSetReader& input,
                                                        const LightfieldAnalysis& analysis,
                                                        uint32_t view,
                                                        const LightfieldEncodeOptions& options);

// The same for frames [first_frame, first_frame + frame_count) of the view only: whole segments
// (options.segment_frames > 0, first_frame a multiple of it and the range ending on a segment
// boundary or at the clip's end). The view's index chunk comes with the range holding frame 0.
// A range short of the whole clip is a partial encoding: its cells' t chunks cover the range only
// and are stored uncompressed, for merge_lightfield_shards() to join (kEncoderInput for a range
// that is not whole segments; the images are checked against the analysis as far as the range
// tells: depths inside its range, no material or HDR colour it did not see).
Expected<LightfieldViewEncoding> encode_lightfield_view_frames(
    const capture::CaptureSetReader& input, const LightfieldAnalysis& analysis, uint32_t view,
    uint32_t first_frame, uint32_t frame_count, const LightfieldEncodeOptions& options);

// Joins the t chunks of consecutive whole segments of one cell (raw bytes, in frame order, each
// with its frame count) into the cell's t chunk for all of them, raw: exactly what an encode of
// the whole range writes. Errors: kLightfieldChunk (a t chunk that does not parse).
Expected<std::vector<uint8_t>> join_t_chunks(std::span<const std::vector<uint8_t>> parts,
                                             std::span<const uint32_t> frame_counts);

// ---- Assembly ----

// Writes one lightfield track: the analysis's header first, then each view's chunks as they are
// appended, in view order 0, 1, ..., view_count - 1. The bytes equal encode_lightfield()'s
// whoever coded the views. Holds a reference to the writer, which must outlive it.
class LightfieldTrackWriter {
 public:
  // Adds the track to `writer` (container errors passed through).
  static Expected<LightfieldTrackWriter> begin(container::Writer& writer,
                                               const LightfieldAnalysis& analysis);
  uint16_t track() const { return track_; }
  // Appends the next view's chunks (kEncoderInput when `view.view` is not the next view).
  Status append(const LightfieldViewEncoding& view);
  // The track's figures, once every view is appended (kEncoderInput before). Does not finish
  // the writer.
  Expected<LightfieldEncodeStats> finish() const;

 private:
  LightfieldTrackWriter(container::Writer& writer, uint16_t track, uint32_t view_count,
                        LightfieldEncodeStats stats)
      : writer_(&writer), track_(track), view_count_(view_count), stats_(stats) {}
  container::Writer* writer_;
  uint16_t track_;
  uint32_t view_count_;
  uint32_t next_view_ = 0;
  LightfieldEncodeStats stats_;
};

// ---- The whole encode ----

// Encodes every view of `input` into a new lightfield track of `writer` (does not finish it):
// analyse_lightfield(), then encode_lightfield_view() and LightfieldTrackWriter::append() view by
// view. Errors: kEncoderOption; the capture reader's (file, face and pixel named);
// kEncoderInput; container and block-codec errors passed through.
Expected<LightfieldEncodeStats> encode_lightfield(const capture::CaptureSetReader& input,
                                                  container::Writer& writer,
                                                  const LightfieldEncodeOptions& options);

// Opens the capture set at `capture_dir`, encodes it into `out_path` (written whole or not at
// all), and sets metadata "encoder" and "source_scene". An `out_path` that is the set's
// directory, its manifest or one of its images is refused first (kOutputIsInput, naming both).
Expected<LightfieldEncodeStats> encode_lightfield_file(const std::filesystem::path& capture_dir,
                                                       const std::string& out_path,
                                                       const LightfieldEncodeOptions& options);

// The RDO lambda an encode uses for colour coded as `coding` (kBc1 / kBc6h / kBc7; the resolved
// format, not kAuto): options.colour_rdo, or, when that is kColourRdoAuto, the format's default
// (BC1 12, BC6H and BC7 0.5; BC6H kDenoisedBc6hRdo when noise_psnr_db > 0 and denoise_window > 1).
// BC1's differs because a BC1 candidate saves at most 30 estimated
// bits where a BC6H / BC7 one saves 104, so the same lambda buys far fewer bytes (at 0.5: BC1
// 10-27 % of its colour bytes, BC6H 31-69 %, docs/ENCODER.md).
double colour_rdo_lambda(const LightfieldEncodeOptions& options, ColourCoding coding);

// A cell of linear RGB (w * h * 3 floats) as the spatial codec alone would show it: coded in
// `coding` (not kAuto) exactly as a keyframe is (BC1 with `bc1_fit`), then decoded to linear
// RGB. This is the reference Q is measured against; tests use it to check decoded files.
Status spatial_colour_reference(ColourCoding coding, Bc1Fit bc1_fit, std::span<const float> rgb,
                                uint32_t w, uint32_t h, std::vector<float>* shown);

// HDR metric: 10 log10(8^2 / MSE) over log2(max(v, 2^-14)) of every channel, i.e. PSNR in stops
// with an 8-stop peak (+inf when identical). 50 dB is an RMS error of 0.025 stops (~1.8 %).
double psnr_log2(std::span<const float> reference, std::span<const float> test);

}  // namespace calf::encoder
