// Keyframes and render noise (docs/ENCODER.md "Keyframes and render noise"): encodes a capture
// set with the colour keyframe threshold Q at 50 dB (calf-encode --psnr 50) and at --psnr auto
// for each margin, noise factor and pre-filter window given (calf/encoder/noise_estimate.h,
// colour_denoise.h; the window applies where --psnr auto turns the noise-aware test on, as
// calf-encode's --denoise-window auto does), and prints per encode the colour stream's stored
// bytes, its keyframes, the encode's wall time and the PSNR of the decoded colour (every face of
// every view and frame, 8-bit sRGB as calf-bench's peers measure it, one MSE over everything)
// against the input and against a reference capture of the same viewpoints (--reference: the scene
// rendered converged, ground truth at the capture's own texels). Prints markdown.
//
//   bench-noise_keyframes --capture NOISY [--reference CONVERGED] [--margin 4 --margin 6 ...]
//       [--factor 0 --factor 3 ...] [--window 0 --window 4 ...] [--rdo auto --rdo 1 ...]
//       [--threads N]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/capture/capture_set.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/encoder/colour_denoise.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/noise_estimate.h"
#include "calf/format/colour.h"
#include "calf/format/container.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;

// Every face of every view and frame of a capture set as sRGB bytes, view-major.
Expected<std::vector<uint8_t>> capture_srgb(const fs::path& dir) {
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader in, capture::CaptureSetReader::open(dir));
  const auto& m = in.manifest();
  std::vector<uint8_t> out;
  capture::ViewFrame vf;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      CALF_RETURN_IF_ERROR(in.read(v, f, &vf));
      for (const float c : vf.color) out.push_back(srgb8_from_linear(c));
    }
  }
  return out;
}

// The clip's decoded colour in the same layout.
Expected<std::vector<uint8_t>> clip_srgb(const fs::path& clip) {
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(clip.string()));
  CALF_ASSIGN_OR_RETURN(decoder::LightfieldReference ref,
                        decoder::LightfieldReference::open(reader, 0));
  const auto& h = ref.header();
  std::vector<uint8_t> out;
  decoder::LightfieldFace face;
  for (uint32_t v = 0; v < h.view_count; ++v) {
    for (uint32_t f = 0; f < h.frame_count; ++f) {
      for (uint32_t i = 0; i < 6; ++i) {
        CALF_RETURN_IF_ERROR(ref.decode_face(v, i, f, &face));
        for (const float c : face.colour) out.push_back(srgb8_from_linear(c));
      }
    }
  }
  return out;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a.size() != b.size() || a.empty()) return NAN;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    sum += d * d;
  }
  return sum == 0 ? INFINITY : 10.0 * std::log10(255.0 * 255.0 * a.size() / sum);
}

int fail(const Status& s) {
  std::fprintf(stderr, "bench-noise_keyframes: %s\n", s.to_string().c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-noise_keyframes: colour bytes and PSNR at --psnr 50 and --psnr auto"};
  std::string capture_dir, reference_dir;
  std::vector<double> margins, factors;
  std::vector<uint32_t> windows;
  std::vector<std::string> rdos;
  uint32_t threads = 0;
  app.add_option("--capture", capture_dir, "the capture set encoded")->required();
  app.add_option("--reference", reference_dir,
                 "a converged capture of the same viewpoints, frames and face size");
  app.add_option("--margin", margins,
                 "--psnr-noise-margin values (repeatable; default: the "
                 "default margin)");
  app.add_option("--factor", factors,
                 "--psnr-noise-factor values (repeatable; default: the default factor)");
  app.add_option("--window", windows,
                 "--denoise-window values (repeatable; default: the default window; 0 = off)")
      ->check(CLI::Range(0u, encoder::kMaxDenoiseWindow));
  app.add_option("--rdo", rdos,
                 "--colour-rdo values of the --psnr auto encodes (repeatable; default: auto)");
  app.add_option("--threads", threads, "encoder threads, 0 = all cores (default 0)");
  CLI11_PARSE(app, argc, argv);
  if (margins.empty()) margins.push_back(encoder::kDefaultPsnrNoiseMargin);
  if (factors.empty()) factors.push_back(encoder::kDefaultNoiseFactor);
  if (windows.empty()) windows.push_back(encoder::kDefaultDenoiseWindow);
  if (rdos.empty()) rdos.push_back("auto");

  auto input = capture::CaptureSetReader::open(capture_dir);
  if (!input.ok()) return fail(input.status());
  encoder::NoiseEstimateOptions no;
  no.threads = threads;
  const auto t0 = std::chrono::steady_clock::now();
  auto noise = encoder::estimate_capture_noise(*input, encoder::ColourCoding::kAuto, no);
  if (!noise.ok()) return fail(noise.status());
  const double estimate_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  auto in_rgb = capture_srgb(capture_dir);
  if (!in_rgb.ok()) return fail(in_rgb.status());
  std::optional<std::vector<uint8_t>> ref_rgb;
  if (!reference_dir.empty()) {
    auto r = capture_srgb(reference_dir);
    if (!r.ok()) return fail(r.status());
    ref_rgb = std::move(*r);
  }

  std::printf("capture %s: noise estimate %s (%s, %llu samples, %.2f s)%s\n\n", capture_dir.c_str(),
              noise->set.psnr_db ? fmt::format("{:.2f} dB", *noise->set.psnr_db).c_str() : "none",
              noise->metric == encoder::NoiseMetric::kLog2 ? "log2-PSNR" : "sRGB PSNR",
              static_cast<unsigned long long>(noise->set.samples), estimate_s,
              ref_rgb
                  ? fmt::format("; input vs reference {:.2f} dB", psnr(*in_rgb, *ref_rgb)).c_str()
                  : "");
  std::printf(
      "| --psnr | Q (dB) | colour bytes | × Q 50 | keyframes | encode s | vs input (dB) |%s\n",
      ref_rgb ? " vs reference (dB) | Δ vs Q 50 (dB) |" : "");
  std::printf("|---|---:|---:|---:|---:|---:|---:|%s\n", ref_rgb ? "---:|---:|" : "");
  const fs::path clip = fs::temp_directory_path() /
                        fmt::format("bench-noise_keyframes-{}.calf", static_cast<long>(getpid()));
  struct Run {
    std::string label;
    double q = 50;
    double noise_db = 0;
    double factor = 0;
    uint32_t window = 0;
    double rdo = encoder::kColourRdoAuto;
  };
  std::vector<Run> runs = {{"50", 50.0, 0, 0, 0, encoder::kColourRdoAuto}};
  for (const double m : margins) {
    for (const double k : factors) {
      for (const uint32_t w : windows) {
        for (const std::string& r : rdos) {
          const double noise_db = encoder::auto_noise_psnr_db(noise->set, m);
          const double rdo = r == "auto" ? encoder::kColourRdoAuto : std::stod(r);
          runs.push_back({fmt::format("auto, margin {:g}, factor {:g}, window {}{}", m, k, w,
                                      r == "auto" ? std::string() : ", colour-rdo " + r),
                          encoder::auto_psnr_db(noise->set, m), noise_db, k, noise_db > 0 ? w : 0,
                          rdo});
        }
      }
    }
  }
  uint64_t base_bytes = 0;
  double base_ref = 0;
  for (const auto& [label, q, noise_db, factor, window, rdo] : runs) {
    encoder::LightfieldEncodeOptions o;
    o.threads = threads;
    o.min_psnr_db = q;
    o.noise_psnr_db = noise_db;
    o.noise_factor = factor;
    o.denoise_window = window;
    o.colour_rdo = rdo;
    const auto e0 = std::chrono::steady_clock::now();
    auto stats = encoder::encode_lightfield_file(capture_dir, clip.string(), o);
    if (!stats.ok()) return fail(stats.status());
    const double encode_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - e0).count();
    auto out_rgb = clip_srgb(clip);
    if (!out_rgb.ok()) return fail(out_rgb.status());
    const uint64_t bytes = stats->colour.stored;
    if (base_bytes == 0) base_bytes = bytes;
    const double vs_ref = ref_rgb ? psnr(*ref_rgb, *out_rgb) : NAN;
    if (label == "50") base_ref = vs_ref;
    std::printf(
        "| %s | %.2f | %llu | %.3f | %llu of %llu | %.2f | %.2f |", label.c_str(), q,
        static_cast<unsigned long long>(bytes),
        static_cast<double>(bytes) / static_cast<double>(base_bytes),
        static_cast<unsigned long long>(stats->colour_keyframes),
        static_cast<unsigned long long>(stats->colour_cells * input->manifest().frame_count),
        encode_s, psnr(*in_rgb, *out_rgb));
    if (ref_rgb) std::printf(" %.2f | %+.2f |", vs_ref, vs_ref - base_ref);
    std::printf("\n");
    std::fflush(stdout);
  }
  std::error_code ec;
  fs::remove(clip, ec);
  return 0;
}
