// bench-bc_bench: encode / decode speed (Mpix/s, one thread) and quality of every BCn encoder
// and quality knob on a fixed test set, printed as a table.
//
// LDR set (512x512 RGBA8 each): smooth gradient, value noise ("texture"), hard edges (stripes
// and checkers), white noise, and "render": a procedurally rendered shaded scene (value-noise
// albedo on a lit sphere over a textured floor with a soft shadow), standing in for a
// calf-capture frame. HDR set (512x512 RGB float): exponential ramp over 24 stops, a sunlit
// "render" (sky gradient, sun disc at 20000, shaded ground), and log-uniform noise.
// Capture images (--capture DIR, repeatable): view-frames of a capture set written by
// calf-capture (format/CAPTURE.md), each the six faces as one N x 6N strip. LDR formats get the
// linear colour as sRGB 8-bit (clamped to [0, 1]); BC6H gets the linear float colour, HDR kept.
// --capture-views limits how many views of each set are used (frames: all of them).
// Metrics: PSNR on 8-bit RGB (BC1/BC7), on R (BC4) or RG (BC5); for BC6H "log2-PSNR": PSNR of
// log2(max(|v|, 2^-14)) per channel with the reference's log2 range as the peak.
// Each timing is the median of --repeats runs; speeds are decoded-texel Mpix/s.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"
#include "calf/format/colour.h"

namespace {

using namespace calf::bc;
constexpr uint32_t N = 512;

float hash01(int x, int y, int s) {
  uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u +
               static_cast<uint32_t>(s) * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return static_cast<float>((h ^ (h >> 16)) & 0xffffff) / 16777215.0f;
}
// Smooth value noise with a few octaves, in [0, 1].
float value_noise(float x, float y, int seed) {
  float sum = 0, amp = 0.5f, norm = 0;
  for (int o = 0; o < 4; ++o) {
    const int xi = static_cast<int>(std::floor(x)), yi = static_cast<int>(std::floor(y));
    float fx = x - xi, fy = y - yi;
    fx = fx * fx * (3 - 2 * fx), fy = fy * fy * (3 - 2 * fy);
    const float a = hash01(xi, yi, seed + o), b = hash01(xi + 1, yi, seed + o);
    const float c = hash01(xi, yi + 1, seed + o), d = hash01(xi + 1, yi + 1, seed + o);
    sum += amp * ((a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy);
    norm += amp, amp *= 0.5f, x *= 2.03f, y *= 2.03f;
  }
  return sum / norm;
}

// Linear radiance of the procedural scene at pixel (x, y); `sun` scales the sun for HDR.
void render(uint32_t x, uint32_t y, float sun, float* rgb) {
  const float u = (x + 0.5f) / N * 2 - 1, v = 1 - (y + 0.5f) / N * 2;
  const float lx = 0.5f, ly = 0.7f, lz = 0.5f;  // light direction (normalised below)
  const float ll = std::sqrt(lx * lx + ly * ly + lz * lz);
  const float cx = 0.0f, cy = 0.1f, r = 0.45f;
  const float dx = u - cx, dy = v - cy, d2 = dx * dx + dy * dy;
  if (d2 < r * r) {  // sphere
    const float nz = std::sqrt(r * r - d2) / r, nx = dx / r, ny = dy / r;
    const float lambert = std::max(0.0f, (nx * lx + ny * ly + nz * lz) / ll);
    const float n = value_noise(u * 8 + 10, v * 8, 3);
    const float alb[3] = {0.8f * n + 0.1f, 0.3f + 0.4f * n, 0.15f};
    const float spec = std::pow(std::max(0.0f, nz), 40.0f) * sun * 0.05f;
    for (int c = 0; c < 3; ++c) rgb[c] = alb[c] * (0.05f + lambert * sun * 0.01f) + spec;
  } else if (v < -0.2f) {  // floor with checker + noise, soft shadow
    const float fu = u / (-v), fv = 1 / (-v);
    const bool check =
        (static_cast<int>(std::floor(fu * 2)) + static_cast<int>(std::floor(fv * 2))) & 1;
    const float n = value_noise(fu * 6, fv * 6, 9);
    const float sd = std::hypot(u + 0.2f, (v + 0.55f) * 3);
    const float shadow = std::clamp((sd - 0.25f) / 0.3f, 0.25f, 1.0f);
    for (int c = 0; c < 3; ++c)
      rgb[c] = (check ? 0.6f : 0.25f) * (0.7f + 0.3f * n) * (c == 2 ? 0.8f : 1.0f) * shadow * sun *
               0.008f;
  } else {  // sky, with a sun disc
    const float t = (v + 0.2f) / 1.2f;
    rgb[0] = (0.3f + 0.2f * (1 - t)) * sun * 0.004f;
    rgb[1] = (0.5f + 0.2f * (1 - t)) * sun * 0.004f;
    rgb[2] = 0.9f * sun * 0.004f;
    if (std::hypot(u - 0.6f, v - 0.7f) < 0.05f) rgb[0] = rgb[1] = rgb[2] = sun * 200;
  }
}

// An image of the test set: w x h texels, RGBA8 (LDR) or RGB float (HDR). `group` is
// "synthetic" or "capture" (means are printed per group).
struct Ldr {
  std::string name;
  std::vector<uint8_t> px;
  uint32_t w = N, h = N;
  std::string group = "synthetic";
};
struct Hdr {
  std::string name;
  std::vector<float> px;
  uint32_t w = N, h = N;
  std::string group = "synthetic";
};

// Appends the view-frames of the capture set in `dir` (views 0 .. max_views - 1, every frame; 0:
// all views) to the LDR and HDR sets. Returns false (after printing why) on any error.
bool load_capture(const std::string& dir, uint32_t max_views, std::vector<Ldr>* ldr,
                  std::vector<Hdr>* hdr) {
  auto reader = calf::capture::CaptureSetReader::open(dir);
  if (!reader.ok()) {
    fmt::print(stderr, "{}\n", reader.status().to_string());
    return false;
  }
  const auto& m = reader->manifest();
  const uint32_t views = max_views == 0 ? static_cast<uint32_t>(m.viewpoints.size())
                                        : std::min<uint32_t>(max_views, m.viewpoints.size());
  const std::string scene =
      m.scene.empty() ? std::filesystem::path(dir).filename().string() : m.scene;
  calf::capture::ViewFrame vf;
  for (uint32_t v = 0; v < views; ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      const calf::Status st = reader->read(v, f, &vf);
      if (!st.ok()) {
        fmt::print(stderr, "{}\n", st.to_string());
        return false;
      }
      const uint32_t w = vf.face_size, h = 6 * vf.face_size;
      const size_t texels = vf.texel_count();
      std::string name = scene;
      if (views > 1) name += fmt::format("/v{}", v);
      if (m.frame_count > 1) name += fmt::format("/f{}", f);
      Ldr l{name, std::vector<uint8_t>(texels * 4, 255), w, h, "capture"};
      float peak = 0;
      size_t over = 0;
      for (size_t i = 0; i < texels; ++i) {
        for (int c = 0; c < 3; ++c) {
          l.px[i * 4 + c] = calf::srgb8_from_linear(vf.color[i * 3 + c]);
          peak = std::max(peak, vf.color[i * 3 + c]);
        }
        over += std::max({vf.color[i * 3], vf.color[i * 3 + 1], vf.color[i * 3 + 2]}) > 1.0f;
      }
      fmt::print("capture {}: {} x {} ({} faces of {}), peak linear {:.3g}, {:.2f}% texels > 1\n",
                 name, w, h, 6, vf.face_size, peak, 100.0 * over / texels);
      ldr->push_back(std::move(l));
      hdr->push_back({name, vf.color, w, h, "capture"});
    }
  }
  return true;
}

std::vector<Ldr> ldr_set() {
  std::vector<Ldr> set = {
      {"gradient", {}}, {"texture", {}}, {"edges", {}}, {"noise", {}}, {"render", {}}};
  std::mt19937 rng(42);
  for (auto& s : set) s.px.assign(N * N * 4, 255);
  for (uint32_t y = 0; y < N; ++y)
    for (uint32_t x = 0; x < N; ++x) {
      const size_t p = (size_t{y} * N + x) * 4;
      set[0].px[p] = static_cast<uint8_t>(x / 2), set[0].px[p + 1] = static_cast<uint8_t>(y / 2);
      set[0].px[p + 2] = static_cast<uint8_t>(255 - (x + y) / 4);
      for (int c = 0; c < 3; ++c)
        set[1].px[p + c] = static_cast<uint8_t>(255 * value_noise(x / 24.0f, y / 24.0f, 7 * c));
      const bool a = ((x + 2 * y) / 13) % 2, b = (x / 32 + y / 32) % 2;
      set[2].px[p] = a ? 240 : 16, set[2].px[p + 1] = b ? 220 : 30,
      set[2].px[p + 2] = a ^ b ? 200 : 60;
      for (int c = 0; c < 3; ++c) set[3].px[p + c] = static_cast<uint8_t>(rng());
      float rgb[3];
      render(x, y, 100.0f, rgb);
      for (int c = 0; c < 3; ++c) set[4].px[p + c] = calf::srgb8_from_linear(rgb[c]);
    }
  return set;
}

std::vector<Hdr> hdr_set() {
  std::vector<Hdr> set = {{"ramp24", {}}, {"render", {}}, {"lognoise", {}}};
  std::mt19937 rng(43);
  std::uniform_real_distribution<float> u(-10, 14);
  for (auto& s : set) s.px.assign(N * N * 3, 0);
  for (uint32_t y = 0; y < N; ++y)
    for (uint32_t x = 0; x < N; ++x) {
      const size_t p = (size_t{y} * N + x) * 3;
      for (int c = 0; c < 3; ++c) {
        set[0].px[p + c] = std::exp2(-10.0f + 24.0f * x / N + 0.3f * c) * (1 + y / float(N));
        set[2].px[p + c] = std::exp2(u(rng));
      }
      render(x, y, 100.0f, &set[1].px[p]);
    }
  return set;
}

double median_seconds(int repeats, const std::function<void()>& fn) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    const auto a = std::chrono::steady_clock::now();
    fn();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

double psnr8(const std::vector<uint8_t>& ref, const std::vector<uint8_t>& dec, int tb, int nc) {
  const size_t texels = ref.size() / 4;
  double se = 0;
  for (size_t i = 0; i < texels; ++i)
    for (int c = 0; c < nc; ++c) se += std::pow(double(dec[i * tb + c]) - ref[i * 4 + c], 2);
  const double mse = se / (double(texels) * nc);
  return mse <= 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
}

double log2_psnr(const std::vector<float>& ref, const std::vector<uint16_t>& dec) {
  auto l2 = [](float v) { return std::log2(std::max(std::fabs(v), 0x1p-14f)); };
  double lo = 1e9, hi = -1e9, se = 0;
  for (float v : ref) lo = std::min(lo, double(l2(v))), hi = std::max(hi, double(l2(v)));
  for (size_t i = 0; i < ref.size(); ++i) se += std::pow(l2(half_to_float(dec[i])) - l2(ref[i]), 2);
  const double mse = se / ref.size();
  return mse <= 0 ? 99.0 : 10 * std::log10((hi - lo) * (hi - lo) / mse);
}

// Sums over the images of one group, for its MEAN line.
struct Sums {
  double psnr = 0, enc = 0, dec = 0, mpix = 0;
  int count = 0;
  void add(double p, double te, double td, double mp) {
    psnr += p, enc += te, dec += td, mpix += mp, ++count;
  }
};

void print_row(const std::string& format, int q, const std::string& image, double enc_mpix_s,
               double dec_mpix_s, double psnr) {
  fmt::print("{:<10} {:>2} {:<16} {:>10.2f} {:>10.1f} {:>9.2f}\n", format, q, image, enc_mpix_s,
             dec_mpix_s, psnr);
}

constexpr const char* kGroups[] = {"synthetic", "capture"};
int group_index(const std::string& group) {
  return group == "capture" ? 1 : 0;
}

// One MEAN line per group present (speeds: total pixels / total time; PSNR: mean over images);
// records each group's mean PSNR in `mean_psnr[group]`.
void print_means(const std::string& format, int q, const std::vector<Sums>& sums,
                 double* mean_psnr) {
  for (int g = 0; g < 2; ++g) {
    const Sums& s = sums[g];
    if (s.count == 0) continue;
    mean_psnr[g] = s.psnr / s.count;
    print_row(format, q, std::string("MEAN/") + kGroups[g], s.mpix / s.enc, s.mpix / s.dec,
              mean_psnr[g]);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"BCn encoder/decoder benchmark: Mpix/s (1 thread) and PSNR per format and quality"};
  int repeats = 3;
  bool quick = false, no_synthetic = false;
  std::vector<std::string> captures;
  uint32_t capture_views = 1;
  app.add_option("--repeats", repeats, "timing repetitions (median reported)");
  app.add_flag("--quick", quick, "skip the slowest settings (BC1 q2, BC7 q2, BC6H q2)");
  app.add_option(
      "--capture", captures,
      "a capture set directory written by calf-capture (repeatable): its colour "
      "view-frames join the test set (sRGB 8-bit for LDR formats, linear float for BC6H)");
  app.add_option("--capture-views", capture_views,
                 "views used per capture set, from view 0 (0: all); every frame of each view");
  app.add_flag("--no-synthetic", no_synthetic, "only the capture images (needs --capture)");
  CLI11_PARSE(app, argc, argv);
  if (no_synthetic && captures.empty()) {
    fmt::print(stderr, "--no-synthetic needs at least one --capture DIR\n");
    return 2;
  }

  std::vector<Ldr> ldr;
  std::vector<Hdr> hdr;
  if (!no_synthetic) ldr = ldr_set(), hdr = hdr_set();
  for (const auto& dir : captures)
    if (!load_capture(dir, capture_views, &ldr, &hdr)) return 1;

  fmt::print("{:<10} {:>2} {:<16} {:>10} {:>10} {:>9}\n", "format", "q", "image", "enc Mpix/s",
             "dec Mpix/s", "PSNR dB");
  struct Row {
    Format f;
    int q;
    bool refine = false;  // BC1: Bc1Options::refine after the fit ("BC1+ref")
  };
  const Row ldr_rows[] = {{Format::kBc1, 0}, {Format::kBc1, 0, true}, {Format::kBc1, 1},
                          {Format::kBc1, 2}, {Format::kBc4, 0},       {Format::kBc4, 1},
                          {Format::kBc5, 0}, {Format::kBc5, 1},       {Format::kBc7, 0},
                          {Format::kBc7, 1}, {Format::kBc7, 2}};
  double bc1_range[2] = {0, 0}, bc7[3][2] = {};
  for (const Row& row : ldr_rows) {
    if (quick && row.q == 2) continue;
    std::vector<Sums> sums(2);
    for (const auto& img : ldr) {
      const uint32_t w = img.w, h = img.h;
      const double mpix = double(w) * h / 1e6;
      std::vector<uint8_t> blocks(encode_bound(row.f, w, h));
      const Image8 view{img.px.data(), w, h, w * 4, 4};
      const double te = median_seconds(repeats, [&] {
        calf::Status st;
        switch (row.f) {
          case Format::kBc1:
            st = encode_bc1(view, blocks.data(), blocks.size(), {row.q, false, 1, row.refine});
            break;
          case Format::kBc4:
            st = encode_bc4(view, blocks.data(), blocks.size(), {row.q, 1});
            break;
          case Format::kBc5:
            st = encode_bc5(view, blocks.data(), blocks.size(), {row.q, 1});
            break;
          default:
            st = encode_bc7(view, blocks.data(), blocks.size(), {row.q, 1});
            break;
        }
        if (!st.ok()) fmt::print("{}\n", st.to_string());
      });
      const int tb = texel_bytes(row.f);
      std::vector<uint8_t> dec(size_t{w} * h * tb);
      const double td = median_seconds(repeats, [&] {
        (void)decode_image(row.f, blocks.data(), blocks.size(), w, h, dec.data(), dec.size(),
                           w * tb)
            .ok();
      });
      const int nc = row.f == Format::kBc4 ? 1 : row.f == Format::kBc5 ? 2 : 3;
      const double p = psnr8(img.px, dec, tb, nc);
      const std::string name = row.refine ? "BC1+ref" : format_name(row.f);
      print_row(name, row.q, img.name, mpix / te, mpix / td, p);
      sums[group_index(img.group)].add(p, te, td, mpix);
    }
    double mean[2] = {0, 0};
    print_means(row.refine ? "BC1+ref" : format_name(row.f), row.q, sums, mean);
    if (row.f == Format::kBc1 && row.q == 0 && !row.refine) std::copy(mean, mean + 2, bc1_range);
    if (row.f == Format::kBc7) std::copy(mean, mean + 2, bc7[row.q]);
  }
  // Acceptance: BC7 at least 3 dB above BC1 range fit on the LDR set.
  for (int g = 0; g < 2; ++g) {
    const bool present = std::any_of(ldr.begin(), ldr.end(),
                                     [&](const Ldr& i) { return group_index(i.group) == g; });
    if (!present) continue;
    for (int q = 0; q <= 2; ++q) {
      if (quick && q == 2) continue;
      fmt::print("BC7 q{} vs BC1 range fit, mean over {} images: {:+.2f} dB\n", q, kGroups[g],
                 bc7[q][g] - bc1_range[g]);
    }
  }
  fmt::print(
      "\nBC6H quality metric: log2-PSNR (PSNR of log2 |v| floored at 2^-14, peak = log2 range)\n");
  for (bool is_signed : {false, true}) {
    for (int q = 0; q <= 2; ++q) {
      if (quick && q == 2) continue;
      std::vector<Sums> sums(2);
      const Format f = is_signed ? Format::kBc6hSigned : Format::kBc6hUnsigned;
      for (const auto& img : hdr) {
        const uint32_t w = img.w, h = img.h;
        const double mpix = double(w) * h / 1e6;
        std::vector<uint8_t> blocks(encode_bound(f, w, h));
        Bc6hOptions o;
        o.quality = q, o.is_signed = is_signed;
        const double te = median_seconds(repeats, [&] {
          (void)encode_bc6h({img.px.data(), w, h, w * 3, 3}, blocks.data(), blocks.size(), o).ok();
        });
        std::vector<uint16_t> dec(size_t{w} * h * 3);
        const double td = median_seconds(repeats, [&] {
          (void)decode_image(f, blocks.data(), blocks.size(), w, h, dec.data(), dec.size() * 2,
                             w * 6)
              .ok();
        });
        const double p = log2_psnr(img.px, dec);
        print_row(format_name(f), q, img.name, mpix / te, mpix / td, p);
        sums[group_index(img.group)].add(p, te, td, mpix);
      }
      double mean[2] = {0, 0};
      print_means(format_name(f), q, sums, mean);
    }
  }
  return 0;
}
