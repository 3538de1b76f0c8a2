// Paper 002 Tables 3 and 4 for calf's view-dependent decoder (decoder/include/calf/decoder/
// lightfield_decoder.h), on encoded clips:
//
// Table 3 — per active-view count (5, 9, all) and with / without view-dependent decoding: the
//   bitrate of the texture updates at 24 fps (colour; depth + material), the decode time per
//   frame (LightfieldDecoder::advance: culling, chunk fetch from the cache / file, zstd or LZMA2
//   decompression, layout undoing), the time a memcpy of the same update bytes takes and the ratio.
//   The eye sits at the centroid of the viewpoints (inside the view volume) and looks in
//   `--directions` horizontal directions in turn; for each it plays the whole clip `--repeats`
//   times (the wrap back to frame 0 is a seek). The first frame of each direction is left out
//   of the means (it uploads everything visible from nothing). Active views: the nearest to the
//   eye (ties by index). The three ways (no VD; VD, eye held; VD, eye turning) play each
//   direction in turn, each with its own decoder, so that load on a shared machine falls on all
//   three alike; besides the wall clock, advance()'s thread CPU time is printed ("CPU ms/frame"),
//   with the VD / no VD ratio of each.
// Table 4 — quadtree leaf levels 1-4 (2x2 ... 16x16 cells per face): per frame, the share of cells
//   visible and the frustum tests of the regular method (every cell) and of the hierarchical one,
//   9 active views (or all, if fewer), one eye, same poses.
// Peers, in the same run where ffmpeg is installed (tests/bench/ffmpeg_peers.h): the depth frames
//   the 9-view decode serves (all six faces of each active view, log-16 codes, stacked into one
//   image per frame), encoded losslessly with FFV1 and with x265, and the time ffmpeg takes to
//   decode them per frame (process start-up included and reported apart).
//
// The limit beside every decode figure: the time to read and decompress just the chunks
//   the frame used (LightfieldFrameUpdates::chunks, each time it was used) plus a memcpy of the
//   frame's update bytes. The decoder runs on one thread by default (no background prefetch), so
//   its time holds every decompression it does.
// --synthetic N: a 9-view clip of N x N faces made by this program (make_synthetic_clip), e.g. the
//   issue's 1024 x 9 views case.
//
//   bench-decoder_tables --clip FILE.calf [--clip ...] [--directions 8] [--repeats 2] [--no-peers]
//       [--no-table4] [--background-thread] [--synthetic 1024 [--synthetic-frames 4]
//       [--synthetic-depth-format raw16|pred16|pred16m] [--synthetic-out FILE]]
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "../integration/synthetic_capture.h"
#include "bench_clock.h"
#include "calf/decoder/culling.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/grid.h"
#include "ffmpeg_peers.h"

namespace {

using namespace calf;
using namespace calf::decoder;

using bench::now_ms;
// advance()'s CPU time: without the background thread every chunk is read and decompressed on
// the calling thread, so its thread CPU time is all of advance()'s work.
using bench::thread_cpu_ms;

struct Poses {
  Vec3 centre;
  std::vector<EyeView> eyes;  // one per direction
};

Poses make_poses(const LightfieldDecoder& d, uint32_t directions) {
  Poses p;
  const uint32_t n = d.header().view_count;
  double far = 1;
  for (uint32_t v = 0; v < n; ++v) {
    p.centre.x += d.view(v).position.x / n;
    p.centre.y += d.view(v).position.y / n;
    p.centre.z += d.view(v).position.z / n;
    far = std::max(far, 2.0 * d.view(v).z_far);
  }
  for (uint32_t i = 0; i < directions; ++i) {
    const double yaw = 2 * std::numbers::pi * i / directions;
    EyeView e;
    e.position = p.centre;
    e.forward = {std::sin(yaw), -0.1, -std::cos(yaw)};
    e.fov_y = std::numbers::pi / 2;
    e.aspect = 1;
    e.near = 0.05;
    e.far = far;
    p.eyes.push_back(e);
  }
  return p;
}

std::vector<uint32_t> nearest_views(const LightfieldDecoder& d, const Vec3& eye, uint32_t count) {
  std::vector<uint32_t> order(d.header().view_count);
  for (uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  auto dist = [&](uint32_t v) {
    const Vec3& q = d.view(v).position;
    return std::hypot(q.x - eye.x, q.y - eye.y, q.z - eye.z);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return dist(a) < dist(b); });
  order.resize(std::min<size_t>(count, order.size()));
  return order;
}

struct Table3Row {
  bool vd = false;
  uint32_t views = 0;
  double colour_mbps = 0, depth_mbps = 0, decode_ms = 0, memcpy_ms = 0, visible_pct = 0;
  double culling_ms = 0, decompress_ms = 0;  // limit = decompress_ms + memcpy_ms
  double cpu_ms = 0;                         // advance()'s thread CPU time
  double tests = 0, exact_tests = 0;         // culling tests per frame
  double kept = 0;  // culling decisions kept from earlier frames per frame (GridCuller's memory)
  uint32_t errors = 0;
  uint64_t frames = 0;
};

// The three ways of Table 3, in this order: everything (no VD), VD with the eye held on each
// direction, VD with the eye turning by 0.1° about the vertical every frame (a head never holds
// still: the decoder's visible sets are recomputed every frame, mostly from the culler's memory
// of the decisions that still hold).
struct Table3Mode {
  bool vd, moving;
};
constexpr std::array<Table3Mode, 3> kTable3Modes = {{{false, false}, {true, false}, {true, true}}};

// Plays every direction with each mode in turn (direction by direction, so that a burst of load
// on the shared machine falls on all three alike and their ratios stay fair), each mode with its
// own decoder.
std::array<Table3Row, 3> run_table3(const container::Reader& reader, const Poses& poses,
                                    const std::vector<uint32_t>& active, uint32_t repeats,
                                    bool background) {
  std::array<Table3Row, 3> rows;
  std::array<LightfieldDecoderOptions, 3> options;
  for (size_t m = 0; m < 3; ++m) {
    rows[m].vd = kTable3Modes[m].vd;
    rows[m].views = static_cast<uint32_t>(active.size());
    options[m].view_dependent = kTable3Modes[m].vd;
    options[m].background_thread = background;
  }
  auto d0 = LightfieldDecoder::open(reader, 0, options[0]);
  auto d1 = LightfieldDecoder::open(reader, 0, options[1]);
  auto d2 = LightfieldDecoder::open(reader, 0, options[2]);
  for (const auto* d : {&d0, &d1, &d2}) {
    if (!d->ok()) {
      std::fprintf(stderr, "%s\n", d->status().to_string().c_str());
      std::exit(1);
    }
  }
  const std::array<LightfieldDecoder*, 3> decoders = {&*d0, &*d1, &*d2};
  const uint32_t frames = decoders[0]->header().frame_count;
  std::vector<uint8_t> sink, chunk, scratch;
  LightfieldFrameUpdates fu;
  std::array<double, 3> colour{}, depth{}, visible{};
  for (const EyeView& held : poses.eyes) {
    for (size_t m = 0; m < 3; ++m) {
      LightfieldDecoder& d = *decoders[m];
      Table3Row& row = rows[m];
      const bool moving = kTable3Modes[m].moving;
      d.reset();
      bool first = true;
      uint32_t step = 0;
      for (uint32_t r = 0; r < repeats; ++r) {
        for (uint32_t f = 0; f < frames; ++f, ++step) {
          EyeView eye = held;
          if (moving) {
            const double a = step * (std::numbers::pi / 1800), c = std::cos(a), sn = std::sin(a);
            eye.forward = {held.forward.x * c - held.forward.z * sn, held.forward.y,
                           held.forward.x * sn + held.forward.z * c};
          }
          const double cpu0 = thread_cpu_ms();
          const Status s = d.advance(f, std::span<const EyeView>(&eye, 1), active, &fu);
          const double cpu_ms = thread_cpu_ms() - cpu0;
          if (!s.ok()) {
            std::fprintf(stderr, "%s\n", s.to_string().c_str());
            std::exit(1);
          }
          // The same bytes copied once, as a GPU upload from mapped memory would at best.
          const uint64_t bytes = fu.stats.update_bytes();
          if (sink.size() < bytes) sink.resize(bytes);
          const double t0 = now_ms();
          size_t at = 0;
          for (const TextureUpdate& u : fu.updates) {
            std::memcpy(sink.data() + at, u.bytes.data(), u.bytes.size());
            at += u.bytes.size();
          }
          const double copy_ms = now_ms() - t0;
          // The limit's other half: reading and decompressing just the chunks the frame used
          // (each time it used one, as if nothing were cached), into one reused buffer.
          const double t1 = now_ms();
          for (uint32_t id : fu.chunks) {
            chunk.resize(reader.chunks()[id].raw_size);
            if (!reader.read_chunk_into(id, chunk, scratch).ok()) row.errors += 1;
          }
          const double decompress_ms = now_ms() - t1;
          row.errors += fu.stats.errors;
          if (first) {
            first = false;
            continue;
          }
          row.frames += 1;
          colour[m] += fu.stats.colour_bytes;
          depth[m] += fu.stats.depth_bytes + fu.stats.material_bytes;
          row.decode_ms += fu.stats.decode_ms;
          row.cpu_ms += cpu_ms;
          row.culling_ms += fu.stats.culling_ms;
          row.tests += fu.stats.culling_tests;
          row.exact_tests += fu.stats.culling_exact_tests;
          row.kept += fu.stats.culling_reused;
          row.memcpy_ms += copy_ms;
          row.decompress_ms += decompress_ms;
          visible[m] +=
              fu.stats.total_cells ? double(fu.stats.visible_cells) / fu.stats.total_cells : 0;
        }
      }
    }
  }
  for (size_t m = 0; m < 3; ++m) {
    Table3Row& row = rows[m];
    const double n = std::max<double>(1, row.frames);
    row.colour_mbps = colour[m] / n * 8 * 24 / 1e6;
    row.depth_mbps = depth[m] / n * 8 * 24 / 1e6;
    row.decode_ms /= n;
    row.cpu_ms /= n;
    row.culling_ms /= n;
    row.tests /= n;
    row.exact_tests /= n;
    row.kept /= n;
    row.memcpy_ms /= n;
    row.decompress_ms /= n;
    row.visible_pct = 100 * visible[m] / n;
  }
  return rows;
}

struct Table4Row {
  uint32_t level = 0;
  double visible_pct = 0, regular = 0, hierarchical = 0;
};

Table4Row run_table4(const LightfieldDecoder& d, const Poses& poses,
                     const std::vector<uint32_t>& active, uint32_t level) {
  Table4Row row;
  row.level = level;
  auto grid = FaceGrid::with_regions_per_side(d.header().face_size, 1u << level);
  if (!grid.ok()) return row;
  double visible = 0, total = 0;
  for (const EyeView& eye : poses.eyes) {
    const Frustum f = eye_frustum(eye);
    const std::span<const Frustum> frusta(&f, 1);
    CullStats regular, hierarchical;
    for (uint32_t v : active) {
      const LightfieldViewInfo& info = d.view(v);
      const Vec3 p = info.position;
      // The decoder's far cap (lightfield_decoder.cc): past the viewer's far plane from this
      // viewpoint.
      const double z_far = std::max<double>(
          info.z_far,
          std::hypot(eye.position.x - p.x, eye.position.y - p.y, eye.position.z - p.z) + eye.far);
      for (int face = 0; face < 6; ++face) {
        const CubeFace cf = static_cast<CubeFace>(face);
        (void)visible_cells_brute_force(p, cf, *grid, info.z_near, z_far, frusta, &regular);
        visible +=
            visible_cells_hierarchical(p, cf, *grid, info.z_near, z_far, frusta, 0, &hierarchical)
                .size();
        total += grid->cell_count();
      }
    }
    row.regular += regular.tests;
    row.hierarchical += hierarchical.tests;
  }
  const double n = static_cast<double>(poses.eyes.size());
  row.regular /= n;
  row.hierarchical /= n;
  row.visible_pct = 100 * visible / std::max(1.0, total);
  return row;
}

void run_peers(const container::Reader& reader, const std::vector<uint32_t>& active,
               double calf_ms_per_frame) {
  auto ref = LightfieldReference::open(reader, 0);
  if (!ref.ok()) return;
  const auto& h = ref->header();
  const uint32_t w = h.face_size, faces = static_cast<uint32_t>(active.size()) * 6;
  std::vector<uint16_t> codes(size_t{w} * w * faces * h.frame_count);
  LightfieldFace face;
  size_t at = 0;
  for (uint32_t f = 0; f < h.frame_count; ++f) {
    for (uint32_t v : active) {
      for (uint32_t c = 0; c < 6; ++c) {
        if (!ref->decode_face(v, c, f, &face).ok()) return;
        std::copy(face.depth.begin(), face.depth.end(), codes.begin() + at);
        at += face.depth.size();
      }
    }
  }
  std::printf(
      "\nDepth peers: the same %u frames of %u faces (%u x %u each, stacked), lossless. "
      "ffmpeg's decode ms/frame includes its process start-up; 'marginal' leaves it out "
      "(all frames minus the first, per frame)\n\n",
      h.frame_count, faces, w, w);
  std::printf(
      "| method | bytes | ratio to raw 16-bit | exact | decode ms/frame | marginal ms/frame |\n"
      "|---|---:|---:|---|---:|---:|\n");
  const double raw = static_cast<double>(codes.size()) * 2;
  std::printf("| calf (all faces, no VD, decode incl. colour) | — | — | yes | %.3f | — |\n",
              calf_ms_per_frame);
  for (const bench::PeerResult& p :
       {bench::ffv1_depth(codes, w, w * faces, h.frame_count),
        bench::x265_lossless_depth(codes, w, w * faces, h.frame_count)}) {
    if (!p.available) {
      std::printf("| %s | n/a | | | | | (%s)\n", p.method.c_str(), p.note.c_str());
      continue;
    }
    std::printf("| %s | %llu | %.1f× | %s | %.3f | %.3f |\n", p.method.c_str(),
                static_cast<unsigned long long>(p.bytes), raw / std::max<double>(1, p.bytes),
                p.exact ? "yes" : "NO", p.decode_ms_per_frame, p.marginal_ms_per_frame);
  }
}

// A 9-view clip of face x face texels per cube face made here (no ray tracing): the synthetic
// scene of the integration tests (tests/integration/synthetic_capture.h: smooth colour, a small
// moving square on face 0, a fade on face 2, sky on half of face 3), viewpoints 0.1 apart on a
// line, encoded with the default options (cell 64, 2 x 2 depth regions, raw16 depth, BC1 colour)
// but for the depth coding `depth`. The capture set is written to a temporary directory and
// removed after encoding.
bool make_synthetic_clip(uint32_t face, uint32_t frames, encoder::DepthCoding depth,
                         const std::string& out) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::path(out).parent_path() / (fs::path(out).filename().string() + ".capture");
  fs::remove_all(dir);
  testing_support::SceneSpec scene;
  scene.face = face;
  scene.frames = frames;
  scene.views = 9;
  scene.first_viewpoint = {-0.4, 0, 0};
  scene.viewpoint_step = {0.1, 0, 0};
  const double t0 = now_ms();
  Status s = testing_support::write_synthetic_capture(dir, scene);
  if (s.ok()) {
    encoder::LightfieldEncodeOptions o;
    o.threads = 0;
    o.depth = depth;
    auto stats = encoder::encode_lightfield_file(dir, out, o);
    if (!stats.ok()) s = stats.status();
  }
  fs::remove_all(dir);
  if (!s.ok()) {
    std::fprintf(stderr, "synthetic clip: %s\n", s.to_string().c_str());
    return false;
  }
  std::fprintf(stderr, "synthetic clip %s: 9 views, face %u, %u frames, made in %.1f s\n",
               out.c_str(), face, frames, (now_ms() - t0) / 1000);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Paper 002 Tables 3 and 4 for the view-dependent decoder, with ffmpeg peers"};
  std::vector<std::string> clips;
  uint32_t directions = 8, repeats = 2, synthetic = 0, synthetic_frames = 4;
  std::string synthetic_out = "/tmp/calf-bench-synthetic.calf";
  std::string synthetic_depth = "pred16m";
  bool no_peers = false, no_table4 = false, background = false;
  app.add_option("--clip", clips, "encoded .calf clip (repeatable)");
  app.add_option("--directions", directions, "horizontal look directions (default 8)")
      ->check(CLI::Range(1, 360));
  app.add_option("--repeats", repeats, "plays of the clip per direction (default 2)")
      ->check(CLI::Range(1, 100));
  app.add_flag("--no-peers", no_peers, "skip the ffmpeg FFV1 / x265 depth peers");
  app.add_flag("--no-table4", no_table4, "skip Table 4 (culling test counts per leaf level)");
  app.add_flag("--background-thread", background,
               "decode with the decoder's background prefetch thread (default off: every chunk "
               "is read and decompressed on the one timed thread)");
  app.add_option("--synthetic", synthetic,
                 "also make and measure a 9-view synthetic clip of this face size, e.g. 1024 "
                 "(default 0: none; 1024 takes minutes to make)")
      ->check(CLI::Range(0, 4096));
  app.add_option("--synthetic-frames", synthetic_frames, "frames of the synthetic clip (default 4)")
      ->check(CLI::Range(2, 600));
  app.add_option("--synthetic-depth-format", synthetic_depth,
                 "depth coding of the synthetic clip: pred16m (calf-encode's default), pred16 or "
                 "raw16 (default pred16m)")
      ->check(CLI::IsMember({"raw16", "pred16", "pred16m"}));
  app.add_option("--synthetic-out", synthetic_out,
                 "where the synthetic clip is written and kept (default "
                 "/tmp/calf-bench-synthetic.calf); measure it again with --clip")
      ->check(CLI::NonexistentPath);
  CLI11_PARSE(app, argc, argv);
  if (synthetic != 0) {
    const encoder::DepthCoding depth =
        synthetic_depth == "pred16"    ? encoder::DepthCoding::kRaw16Predicted
        : synthetic_depth == "pred16m" ? encoder::DepthCoding::kRaw16PredictedMasked
                                       : encoder::DepthCoding::kRaw16;
    if (!make_synthetic_clip(synthetic, synthetic_frames, depth, synthetic_out)) return 1;
    clips.push_back(synthetic_out);
  }
  if (clips.empty()) {
    std::fprintf(stderr, "bench-decoder_tables: give --clip or --synthetic\n");
    return 2;
  }

  for (const std::string& path : clips) {
    auto reader = container::Reader::open(path);
    if (!reader.ok()) {
      std::fprintf(stderr, "%s\n", reader.status().to_string().c_str());
      return 1;
    }
    auto probe = LightfieldDecoder::open(*reader, 0);
    if (!probe.ok()) {
      std::fprintf(stderr, "%s: %s\n", path.c_str(), probe.status().to_string().c_str());
      return 1;
    }
    const auto& h = probe->header();
    const Poses poses = make_poses(*probe, directions);
    std::printf(
        "\n## %s\n\n%u views, face %u, cell %u, depth region %u, %u frames; eye at the "
        "viewpoints' centroid, fov 90°, %u directions x %u plays\n\n",
        path.c_str(), h.view_count, h.face_size, h.cell_size, h.depth_region_size, h.frame_count,
        directions, repeats);
    std::printf(
        "Table 3 (decoder %s; limit = reading and decompressing the chunks the frame used + a "
        "memcpy of its update bytes; eye held: one direction for all its frames, moving: turning "
        "0.1° a frame)\n\n| VD | eye | active views | colour Mbps @24fps | "
        "depth+material Mbps | cells visible %% | decode ms/frame | of it culling | limit "
        "ms/frame | decode / limit | VD / no VD | CPU ms/frame | VD / no VD (CPU) | memcpy "
        "ms/frame | decode / memcpy | tests (exact) + kept per frame "
        "|\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        background ? "with its background thread" : "on one thread");
    std::vector<uint32_t> counts;
    for (uint32_t c : {5u, 9u, h.view_count}) {
      const uint32_t k = std::min(c, h.view_count);
      if (std::find(counts.begin(), counts.end(), k) == counts.end()) counts.push_back(k);
    }
    double nine_no_vd_ms = 0;
    for (uint32_t k : counts) {
      const std::vector<uint32_t> active = nearest_views(*probe, poses.centre, k);
      double no_vd_ms = 0, no_vd_cpu_ms = 0;
      const std::array<Table3Row, 3> rows = run_table3(*reader, poses, active, repeats, background);
      for (size_t mode = 0; mode < 3; ++mode) {
        const bool vd = kTable3Modes[mode].vd, moving = kTable3Modes[mode].moving;
        const Table3Row& r = rows[mode];
        if (!vd && k == std::min(9u, h.view_count)) nine_no_vd_ms = r.decode_ms;
        if (!vd) no_vd_ms = r.decode_ms;
        if (!vd) no_vd_cpu_ms = r.cpu_ms;
        const double limit = r.decompress_ms + r.memcpy_ms;
        std::printf(
            "| %s | %s | %u | %.2f | %.2f | %.1f | %.3f | %.3f | %.3f | %.2f | %s | %.3f | %s | "
            "%.4f | %.0f× | %.0f (%.0f) + %.0f |%s\n",
            vd ? "yes" : "no", moving ? "moving" : "held", k, r.colour_mbps, r.depth_mbps,
            r.visible_pct, r.decode_ms, r.culling_ms, limit, r.decode_ms / std::max(1e-9, limit),
            vd ? fmt::format("{:.2f}", r.decode_ms / std::max(1e-9, no_vd_ms)).c_str() : "—",
            r.cpu_ms,
            vd ? fmt::format("{:.2f}", r.cpu_ms / std::max(1e-9, no_vd_cpu_ms)).c_str() : "—",
            r.memcpy_ms, r.decode_ms / std::max(1e-9, r.memcpy_ms), r.tests, r.exact_tests, r.kept,
            r.errors ? fmt::format(" {} chunk errors", r.errors).c_str() : "");
      }
    }
    const std::vector<uint32_t> nine = nearest_views(*probe, poses.centre, 9);
    if (!no_table4)
      std::printf(
          "\nTable 4 (%zu active views, one eye)\n\n| leaf level | cells per face | "
          "visibility %% | tests regular | tests hierarchical |\n|---|---:|---:|---:|---:|\n",
          nine.size());
    for (uint32_t level = 1; level <= 4 && !no_table4; ++level) {
      const Table4Row r = run_table4(*probe, poses, nine, level);
      std::printf("| %u | %u | %.1f | %.0f | %.0f |\n", level, (1u << level) * (1u << level),
                  r.visible_pct, r.regular, r.hierarchical);
    }
    if (!no_peers) run_peers(*reader, nine, nine_no_vd_ms);
  }
  return 0;
}
