// The mesh track's size and speed (format/SPEC.md §11.4) on the built-in scenes (exported as
// scene files, calf/samples/scene_export.h) and a synthetic instanced grid with vertex states:
// per scene the plain arrays (f32 / u32 little-endian, what a naive writer stores), the peers
// (the same plain bytes compressed whole with zstd -19 and LZMA2 preset 6, as calf's container
// does, without §11.4's planes and deltas; and with zstd chunked per prototype as the track is,
// so that objects stay readable one by one), calf's track with zstd and LZMA2, the encode time and
// the time to open the track and decode every prototype and object, beside a memcpy of the
// decoded bytes (the physical floor). Median of --repeats runs, with min and max.
//
//   bench-mesh_track_bench [--frames 8] [--repeats 5] [--grid 200]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/decoder/mesh_track.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/format/container.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"

namespace {

using namespace calf;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Spread {
  double median = 0, min = 0, max = 0;
};
Spread spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v.front(), v.back()};
}

// A grid of n x n quads (2 n^2 triangles) swaying in 4 states, placed 4 times (one moving).
capture::SceneFile grid_scene(uint32_t n, uint32_t frames) {
  capture::SceneFile s;
  s.name = "grid";
  s.frame_count = frames;
  s.fps = 24;
  s.materials.resize(1);
  capture::SceneMesh m;
  for (uint32_t y = 0; y <= n; ++y) {
    for (uint32_t x = 0; x <= n; ++x) {
      m.positions.insert(m.positions.end(),
                         {static_cast<float>(x) * 0.01f, 0.0f, static_cast<float>(y) * 0.01f});
    }
  }
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  }
  for (int k = 0; k < 4; ++k) {
    m.state_times.push_back(0.25f * static_cast<float>(k));
    for (size_t i = 0; i < m.positions.size(); i += 3) {
      m.state_positions.insert(
          m.state_positions.end(),
          {m.positions[i], 0.01f * static_cast<float>(k) * std::sin(m.positions[i] * 7.0f),
           m.positions[i + 2]});
    }
  }
  s.meshes.push_back(m);
  for (int i = 0; i < 4; ++i) {
    capture::SceneObject o{
        "", 0, 0, {{1, 0, 0, 3.0f * static_cast<float>(i), 0, 1, 0, 0, 0, 0, 1, 0}}};
    if (i == 3) {
      o.transforms.clear();
      for (uint32_t f = 0; f < frames; ++f)
        o.transforms.push_back({1, 0, 0, 9, 0, 1, 0, 0.01f * static_cast<float>(f), 0, 0, 1, 0});
    }
    s.objects.push_back(o);
  }
  return s;
}

// The plain arrays of every prototype and object, concatenated.
std::vector<uint8_t> plain_arrays(const capture::SceneFile& s) {
  std::vector<uint8_t> out;
  auto put = [&](const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  };
  for (const auto& m : s.meshes) {
    auto a = encoder::prototype_arrays(m);
    if (!a.ok()) continue;
    const auto& v = a->vertices;
    const auto& t = a->triangles;
    for (const auto* f : {&v.positions, &v.normals, &v.colours, &v.state_times, &v.state_positions})
      put(f->data(), 4 * f->size());
    for (const auto* w : {&t.indices, &t.triangle_materials}) put(w->data(), 4 * w->size());
  }
  for (const auto& o : s.objects) put(o.transforms.data(), 48 * o.transforms.size());
  return out;
}

uint64_t stored_size(const std::vector<uint8_t>& raw, container::Compression c);

// The peer chunked as calf chunks the track: each prototype's plain vertex arrays, its plain
// triangle arrays and each object's transforms compressed apart.
uint64_t per_chunk_plain(const capture::SceneFile& s, container::Compression c) {
  uint64_t total = 0;
  for (const auto& m : s.meshes) {
    auto a = encoder::prototype_arrays(m);
    if (!a.ok()) continue;
    std::vector<uint8_t> v, t;
    auto put = [](std::vector<uint8_t>& out, const void* p, size_t n) {
      const auto* b = static_cast<const uint8_t*>(p);
      out.insert(out.end(), b, b + n);
    };
    const auto& va = a->vertices;
    for (const auto* f :
         {&va.positions, &va.normals, &va.colours, &va.state_times, &va.state_positions})
      put(v, f->data(), 4 * f->size());
    put(t, a->triangles.indices.data(), 4 * a->triangles.indices.size());
    put(t, a->triangles.triangle_materials.data(), 4 * a->triangles.triangle_materials.size());
    total += stored_size(v, c) + stored_size(t, c);
  }
  return total;
}

uint64_t stored_size(const std::vector<uint8_t>& raw, container::Compression c) {
  // The peer: one chunk per 1 GiB at most, as the container would hold it.
  uint64_t total = 0;
  for (size_t at = 0; at < raw.size(); at += container::kMaxRawChunkSize) {
    const size_t n = std::min<size_t>(raw.size() - at, container::kMaxRawChunkSize);
    auto s = container::compress_chunk(std::span<const uint8_t>(raw.data() + at, n), c);
    total += s.ok() ? s->bytes.size() : 0;
  }
  return total;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-mesh_track_bench: mesh track bytes and speed against plain arrays + zstd/xz"};
  uint32_t frames = 8, repeats = 5, grid = 200;
  app.add_option("--frames", frames, "frames of each exported scene (default 8)");
  app.add_option("--repeats", repeats, "timed runs per figure (default 5)");
  app.add_option("--grid", grid, "side of the synthetic grid mesh in quads (default 200)");
  CLI11_PARSE(app, argc, argv);

  std::vector<capture::SceneFile> scenes;
  for (const auto& info : samples::builtin_scenes()) {
    auto scene = samples::make_builtin_scene(info.name);
    if (!scene.ok()) continue;
    auto file = samples::export_scene(*scene, frames);
    if (file.ok()) scenes.push_back(std::move(*file));
  }
  scenes.push_back(grid_scene(grid, frames));

  std::printf(
      "| scene | tris | plain B | zstd(plain) | lzma2(plain) | zstd(plain per chunk) | calf zstd | "
      "calf lzma2 | gain vs zstd(plain) | encode s | decode ms (min-max) | memcpy ms |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& scene : scenes) {
    const auto plain = plain_arrays(scene);
    const uint64_t peer_zstd = stored_size(plain, container::Compression::kZstd);
    const uint64_t peer_lzma = stored_size(plain, container::Compression::kLzma2);
    const uint64_t peer_chunked = per_chunk_plain(scene, container::Compression::kZstd);
    uint64_t calf_bytes[2] = {0, 0};
    std::vector<uint8_t> file;
    std::vector<double> encode_s;
    encoder::MeshEncodeStats stats;
    for (int c = 0; c < 2; ++c) {
      encoder::MeshEncodeOptions o;
      o.supercompression = c ? container::Compression::kLzma2 : container::Compression::kZstd;
      std::vector<uint8_t> bytes;
      auto w = container::Writer::create(container::memory_sink(&bytes));
      const auto t0 = Clock::now();
      if (!w.ok() || !encoder::encode_mesh_track(scene, nullptr, o, &*w, &stats).ok() ||
          !w->finish().ok()) {
        std::fprintf(stderr, "encode failed on %s\n", scene.name.c_str());
        return 1;
      }
      if (c == 0) encode_s.push_back(seconds_since(t0));
      calf_bytes[c] = stats.index.stored + stats.vertices_stream.stored +
                      stats.triangles_stream.stored + stats.visibility.stored;
      if (c == 0) file = std::move(bytes);
    }
    std::vector<double> decode_ms, copy_ms;
    for (uint32_t r = 0; r < repeats; ++r) {
      const auto t0 = Clock::now();
      auto reader =
          container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
      auto track = decoder::MeshTrack::open(*reader, 0);
      if (!track.ok()) return 1;
      std::vector<decoder::MeshPrototype> protos(track->prototype_count());
      std::vector<decoder::MeshObject> objects(track->object_count());
      for (uint32_t i = 0; i < protos.size(); ++i) (void)track->prototype(i, &protos[i]).ok();
      for (uint32_t i = 0; i < objects.size(); ++i) (void)track->object(i, &objects[i]).ok();
      decode_ms.push_back(1e3 * seconds_since(t0));
      const auto t1 = Clock::now();
      std::vector<uint8_t> copy(plain.size());
      std::memcpy(copy.data(), plain.data(), plain.size());
      copy_ms.push_back(1e3 * seconds_since(t1));
      if (copy != plain) return 1;  // keeps the copy from being optimised away
    }
    const Spread d = spread(decode_ms), m = spread(copy_ms);
    std::printf(
        "| %s | %llu | %zu | %llu | %llu | %llu | %llu | %llu | %.2fx | %.2f | %.2f (%.2f-%.2f) | "
        "%.3f "
        "|\n",
        scene.name.c_str(), static_cast<unsigned long long>(stats.triangles), plain.size(),
        static_cast<unsigned long long>(peer_zstd), static_cast<unsigned long long>(peer_lzma),
        static_cast<unsigned long long>(peer_chunked),
        static_cast<unsigned long long>(calf_bytes[0]),
        static_cast<unsigned long long>(calf_bytes[1]),
        calf_bytes[0] ? static_cast<double>(peer_zstd) / static_cast<double>(calf_bytes[0]) : 0.0,
        spread(encode_s).median, d.median, d.min, d.max, m.median);
  }
  return 0;
}
