// Demo of the ffmpeg peers (ffmpeg_peers.h) on synthetic content: one cube face (-Z) of a
// viewpoint watching a sphere roll over a slanted floor, with sky above the horizon.
//   - depth: radial distances turned into log-16 codes with calf's mapping (z_near / z_far
//     measured over the clip, calf/format/log_depth.h; sky = 65535), coded losslessly by FFV1
//     and by x265 on the bit-swizzled codes; round trips checked bit for bit;
//   - colour: the same scene shaded (checkered floor, lit sphere, sky gradient) as 8-bit sRGB
//     (calf/format/colour.h), coded by x265 at the CRF matching each target PSNR.
// Prints markdown tables: method, bytes, ratio to raw, decode ms per frame (min of 3 runs, wall
// time of `ffmpeg -i FILE -f rawvideo -` into a pipe, ffmpeg start-up included), the decode of
// the first frame alone (≈ start-up) and the marginal ms of each further frame. "n/a" where
// ffmpeg or an encoder is missing.
//
//   bench-ffmpeg_depth_peers [--size 256] [--frames 48] [--preset medium]
//                            [--colour-psnr 35 --colour-psnr 40 ...] [--colour-pix-fmt auto]
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/format/colour.h"
#include "calf/format/cube.h"
#include "calf/format/log_depth.h"
#include "ffmpeg_peers.h"

namespace {

using namespace calf;

struct Hit {
  double t = std::numeric_limits<double>::infinity();  // radial distance; inf = sky
  int what = 0;                                        // 0 sky, 1 floor, 2 sphere
  double nx = 0, ny = 0, nz = 0;                       // sphere normal
  double px = 0, pz = 0;                               // floor point (for the checker)
};

// The scene at frame f of n: the floor is the plane y + 0.15 z + 1 = 0 (rising away from the
// viewer, who looks down -z), cut off at 100 units (sky beyond); a sphere of radius 0.7 rolls
// from x = -1.6 to 1.6 at z = -4, touching the floor.
Hit trace(const Vec3& d, uint32_t f, uint32_t n) {
  Hit h;
  const double denom = d.y + 0.15 * d.z;
  if (denom < 0) {
    const double t = -1.0 / denom;
    if (t < 100) {
      h = {t, 1, 0, 0, 0, t * d.x, t * d.z};
    }
  }
  const double s = n > 1 ? double(f) / (n - 1) : 0.0;
  const double cx = -1.6 + 3.2 * s, cz = -4.0, r = 0.7;
  const double cy = r * std::sqrt(1 + 0.15 * 0.15) - 1 - 0.15 * cz;
  // |t d - c|^2 = r^2 with |d| = 1.
  const double b = d.x * cx + d.y * cy + d.z * cz;
  const double c = cx * cx + cy * cy + cz * cz - r * r;
  const double disc = b * b - c;
  if (disc >= 0) {
    const double t = b - std::sqrt(disc);
    if (t > 0 && t < h.t) {
      h = {t, 2, (t * d.x - cx) / r, (t * d.y - cy) / r, (t * d.z - cz) / r, 0, 0};
    }
  }
  return h;
}

struct Clip {
  std::vector<uint16_t> depth;  // frames x size^2 log-16 codes
  std::vector<uint8_t> rgb;     // frames x size^2 x 3 sRGB bytes
  float z_near = 0, z_far = 0;
  double sky_share = 0;
};

Clip make_clip(uint32_t size, uint32_t frames) {
  Clip clip;
  const size_t texels = size_t{size} * size;
  std::vector<float> z(texels * frames);
  clip.rgb.resize(texels * frames * 3);
  float lo = std::numeric_limits<float>::infinity(), hi = 0;
  size_t sky = 0;
  for (uint32_t f = 0; f < frames; ++f) {
    for (uint32_t y = 0; y < size; ++y) {
      for (uint32_t x = 0; x < size; ++x) {
        const Vec3 d = direction_from_texel(CubeFace::kNegZ, x, y, size);
        const Hit h = trace(d, f, frames);
        const size_t i = texels * f + size_t{y} * size + x;
        float rgb[3];
        if (h.what == 0) {
          z[i] = std::numeric_limits<float>::infinity();
          ++sky;
          const float up = static_cast<float>(std::max(0.0, d.y));
          rgb[0] = 0.25f + 0.3f * up, rgb[1] = 0.45f + 0.3f * up, rgb[2] = 0.9f;
        } else {
          z[i] = static_cast<float>(h.t);
          lo = std::min(lo, z[i]);
          hi = std::max(hi, z[i]);
          if (h.what == 1) {
            const bool odd =
                (static_cast<int64_t>(std::floor(h.px)) + static_cast<int64_t>(std::floor(h.pz))) &
                1;
            const float fade = static_cast<float>(1.0 / (1.0 + 0.02 * h.t));
            const float v = (odd ? 0.7f : 0.2f) * fade;
            rgb[0] = v, rgb[1] = v * 0.9f, rgb[2] = v * 0.8f;
          } else {
            // Lambert from a light up, left and behind the viewer, plus ambient.
            const double len = std::sqrt(0.4 * 0.4 + 0.8 * 0.8 + 0.45 * 0.45);
            const double l = std::max(0.0, (-0.4 * h.nx + 0.8 * h.ny + 0.45 * h.nz) / len);
            const float v = static_cast<float>(0.08 + 0.9 * l);
            rgb[0] = v * 0.9f, rgb[1] = v * 0.3f, rgb[2] = v * 0.2f;
          }
        }
        for (int c = 0; c < 3; ++c) clip.rgb[3 * i + c] = srgb8_from_linear(rgb[c]);
      }
    }
  }
  const Expected<LogDepthRange> range = LogDepthRange::covering(lo, hi);
  clip.depth.resize(z.size());
  for (size_t i = 0; i < z.size(); ++i) {
    clip.depth[i] = range.ok() ? range->encode_unchecked(z[i]) : kLog16Sky;
  }
  clip.z_near = range.ok() ? range->z_near() : 0;
  clip.z_far = range.ok() ? range->z_far() : 0;
  clip.sky_share = double(sky) / double(z.size());
  return clip;
}

// The swizzle must be the paper's: checked on hand-worked codes and inverted on all 65536.
bool swizzle_self_check() {
  struct Case {
    uint16_t u;
    uint8_t c0, c1, c2;
  };
  // 0xFFFF: channel 0 has 6 bits (0, 3, ..., 15), channels 1 and 2 five each.
  // bit 15 -> channel 0 bit 5; bit 14 -> channel 2 bit 4; bit 4 -> channel 1 bit 1.
  const Case cases[] = {{0xFFFF, 63, 31, 31}, {0x8000, 32, 0, 0}, {0x4000, 0, 0, 16},
                        {0x0010, 0, 2, 0},    {0x0007, 1, 1, 1},  {0x0000, 0, 0, 0}};
  for (const Case& k : cases) {
    uint8_t c[3];
    bench::swizzle16(k.u, c);
    if (c[0] != k.c0 || c[1] != k.c1 || c[2] != k.c2) return false;
  }
  for (uint32_t u = 0; u < 65536; ++u) {
    uint8_t c[3];
    bench::swizzle16(static_cast<uint16_t>(u), c);
    if (bench::unswizzle16(c) != u) return false;
  }
  return true;
}

std::string bytes_text(uint64_t b) {
  std::string s = std::to_string(b), out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (i && (s.size() - i) % 3 == 0) out += ',';
    out += s[i];
  }
  return out;
}

void print_row(const bench::PeerResult& p, uint64_t raw_bytes, bool lossless) {
  if (!p.available) {
    fmt::print("| {} | n/a | n/a | n/a | n/a | n/a | n/a | {} |\n", p.method, p.note);
    return;
  }
  std::string check =
      lossless ? (p.exact ? "exact" : "DIFFERS") : fmt::format("{:.2f} dB", p.psnr_db);
  if (!lossless) check += fmt::format(" (CRF {:.2f}, {} encodes)", p.crf, p.encodes);
  if (!p.note.empty()) check += "; " + p.note;
  fmt::print("| {} | {} | {:.1f}× | {:.2f} | {:.1f} | {:.2f} | {:.2f} | {} |\n", p.method,
             bytes_text(p.bytes), double(raw_bytes) / double(p.bytes), p.decode_ms_per_frame,
             p.first_frame_ms, p.marginal_ms_per_frame, p.encode_s, check);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ffmpeg FFV1 / x265 peers on synthetic depth (log-16) and colour"};
  uint32_t size = 256, frames = 48;
  std::string preset = "medium", pix_fmt = "auto";
  std::vector<double> targets = {35, 40, 45, 50};
  bool no_colour = false;
  app.add_option("--size", size, "face size in texels (default 256)")->check(CLI::Range(16, 4096));
  app.add_option("--frames", frames, "frames (default 48)")->check(CLI::Range(1, 100000));
  app.add_option("--preset", preset, "x265 preset (default medium)");
  app.add_option("--colour-psnr", targets, "colour PSNR targets in dB (default 35 40 45 50)");
  app.add_option("--colour-pix-fmt", pix_fmt,
                 "x265 pixel format for colour: auto (yuv444p, gbrp above its PSNR cap; default), "
                 "yuv444p, yuv420p, gbrp");
  app.add_flag("--no-colour", no_colour, "skip the colour peer");
  CLI11_PARSE(app, argc, argv);

  if (!swizzle_self_check()) {
    fmt::print(stderr, "bit swizzle self-check failed\n");
    return 1;
  }
  const Clip clip = make_clip(size, frames);
  const uint64_t raw_depth = clip.depth.size() * 2, raw_rgb = clip.rgb.size();

  fmt::print(
      "### Depth: {}² × {} frames of log-16 codes (z_near {:.3f}, z_far {:.3f}, {:.0f} % "
      "sky), raw {} bytes\n\n",
      size, frames, clip.z_near, clip.z_far, 100 * clip.sky_share, bytes_text(raw_depth));
  const char* header =
      "| method | bytes | ratio to raw | decode ms/frame | first frame ms | marginal ms/frame "
      "| encode s | {} |\n|---|---:|---:|---:|---:|---:|---:|---|\n";
  fmt::print(fmt::runtime(header), "round trip");
  fmt::print("| raw u16 | {} | 1.0× | — | — | — | — | — |\n", bytes_text(raw_depth));
  print_row(bench::ffv1_depth(clip.depth, size, size, frames), raw_depth, true);
  print_row(bench::x265_lossless_depth(clip.depth, size, size, frames, preset), raw_depth, true);
  fmt::print("\n");

  if (!no_colour) {
    fmt::print("### Colour: {}² × {} frames of 8-bit sRGB, raw {} bytes\n\n", size, frames,
               bytes_text(raw_rgb));
    fmt::print(fmt::runtime(header), "PSNR");
    for (double t : targets) {
      bench::PeerResult p =
          bench::x265_colour_matched(clip.rgb, size, size, frames, t, 0.25, pix_fmt, preset);
      p.method += fmt::format(" {:.1f} dB", t);
      print_row(p, raw_rgb, false);
    }
    fmt::print("\n");
  }
  return 0;
}
