// The surfels track's size and speed (format/SPEC.md §11.3) on a realistic buffer: N surfels
// (default 100,000) on a unit sphere with smooth colours, in two orders: random (what a
// blue-noise prefix order looks like to a compressor: neighbouring surfels far apart) and sorted
// along a Morton curve (the best case for a compressor, which a prefix order cannot have). Per
// supercompression: bytes per surfel stored, encode ms and decode ms (open the track and decode
// the whole buffer), beside the peers: the plain f32 arrays (36 bytes a surfel) compressed whole,
// the same 13-byte codes interleaved surfel by surfel instead of in §11.3.3's planes, and a memcpy
// of the decoded floats (the physical floor). Median of --repeats runs, with min and max.
//
//   bench-surfels_track_bench [--surfels 100000] [--repeats 3]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/decoder/surfels_track.h"
#include "calf/encoder/surfels_encode.h"
#include "calf/format/container.h"

namespace {

using namespace calf;
using Clock = std::chrono::steady_clock;
using container::Compression;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Spread {
  double median = 0, min = 0, max = 0;
};
Spread spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v.front(), v.back()};
}

uint64_t splitmix(uint64_t& s) {
  uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Surfels on a unit sphere as a 512^2 G-buffer would see them (positions snapped to a 1/256
// grid), normals from the sphere, colours a smooth gradient; in random order.
encoder::SurfelPrototypeInput sphere(uint32_t n) {
  encoder::SurfelPrototypeInput in;
  uint64_t s = 42;
  for (uint32_t i = 0; i < n; ++i) {
    const double z = 2 * (splitmix(s) >> 11) * 0x1p-53 - 1;
    const double phi = 2 * M_PI * (splitmix(s) >> 11) * 0x1p-53;
    const double r = std::sqrt(1 - z * z);
    const double d[3] = {r * std::cos(phi), r * std::sin(phi), z};
    for (int c = 0; c < 3; ++c) {
      in.positions.push_back(static_cast<float>(std::round(d[c] * 256) / 256));
      in.normals.push_back(static_cast<float>(d[c]));
    }
    in.colours.push_back(static_cast<float>(0.2 + 0.6 * (0.5 + 0.5 * d[0])));
    in.colours.push_back(static_cast<float>(0.3 + 0.4 * (0.5 + 0.5 * d[1])));
    in.colours.push_back(static_cast<float>(0.1 + 0.3 * (0.5 + 0.5 * d[2])));
  }
  in.prefix_count = std::min<uint32_t>(n, 1000);
  in.prefix_radius = static_cast<float>(std::sqrt(4 * M_PI / in.prefix_count) * 0.5);
  return in;
}

uint64_t morton(const float* p) {
  uint64_t code = 0;
  for (int bit = 20; bit >= 0; --bit) {
    for (int c = 0; c < 3; ++c) {
      const auto q = static_cast<uint32_t>((p[c] + 1.0f) * 0.5f * ((1u << 21) - 1));
      code = code << 1 | ((q >> bit) & 1);
    }
  }
  return code;
}

encoder::SurfelPrototypeInput morton_sorted(const encoder::SurfelPrototypeInput& in) {
  std::vector<uint32_t> order(in.size());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<uint64_t> keys(in.size());
  for (size_t i = 0; i < in.size(); ++i) keys[i] = morton(&in.positions[3 * i]);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  encoder::SurfelPrototypeInput out = in;
  for (size_t i = 0; i < order.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      out.positions[3 * i + c] = in.positions[3 * order[i] + c];
      out.normals[3 * i + c] = in.normals[3 * order[i] + c];
      out.colours[3 * i + c] = in.colours[3 * order[i] + c];
    }
  }
  return out;
}

// A surfels track alone (its pairing is not checked here: open() needs a mesh kind at
// mesh_track, so an empty mesh track header goes first).
std::vector<uint8_t> encode(const encoder::SurfelPrototypeInput& in, Compression c) {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  (void)w->add_track(container::MeshTrackHeader{}).status();
  encoder::SurfelsTrackInput input;
  input.prototypes.push_back(in);
  encoder::SurfelsEncodeOptions o;
  o.supercompression = c;
  const Status st = encoder::encode_surfels_track(input, o, &*w);
  if (!st.ok()) std::fprintf(stderr, "%s\n", st.to_string().c_str());
  (void)w->finish().ok();
  return file;
}

uint64_t stored_bytes(const std::vector<uint8_t>& file) {
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  uint64_t n = 0;
  for (const auto& c : r->chunks()) {
    if (c.keys.track == 1 && c.keys.stream == 1) n += c.stored_size;
  }
  return n;
}

uint64_t compressed(const std::vector<uint8_t>& raw, Compression c) {
  auto s = container::compress_chunk(raw, c);
  return s.ok() ? s->bytes.size() : 0;
}

const char* name(Compression c) {
  return c == Compression::kNone ? "none" : c == Compression::kZstd ? "zstd-19" : "lzma2-6";
}

void run(const char* order, const encoder::SurfelPrototypeInput& in, int repeats) {
  const double n = static_cast<double>(in.size());
  // Peers: plain f32 arrays, and the codes interleaved surfel by surfel.
  std::vector<uint8_t> plain;
  for (const auto* a : {&in.positions, &in.normals, &in.colours}) {
    const auto* b = reinterpret_cast<const uint8_t*>(a->data());
    plain.insert(plain.end(), b, b + 4 * a->size());
  }
  surfels::PrototypeRecord box;
  for (int c = 0; c < 3; ++c) box.box_min[c] = -1, box.box_max[c] = 1;
  const auto codes = encoder::quantise_surfels(in, box);
  std::vector<uint8_t> interleaved;
  for (size_t i = 0; i < codes.size(); ++i) {
    for (int c = 0; c < 3; ++c)
      interleaved.push_back(static_cast<uint8_t>(codes.positions[3 * i + c])),
          interleaved.push_back(static_cast<uint8_t>(codes.positions[3 * i + c] >> 8));
    for (int c = 0; c < 2; ++c)
      interleaved.push_back(static_cast<uint8_t>(codes.normals[2 * i + c])),
          interleaved.push_back(static_cast<uint8_t>(codes.normals[2 * i + c] >> 8));
    for (int c = 0; c < 3; ++c) interleaved.push_back(codes.colours[3 * i + c]);
  }
  std::printf("\n%s order, %zu surfels\n", order, in.size());
  std::printf("| coding | bytes/surfel | encode ms (min-max) | decode ms (min-max) |\n");
  std::printf("|---|---:|---:|---:|\n");
  for (Compression c : {Compression::kZstd, Compression::kLzma2}) {
    std::printf("| peer: plain f32, %s whole | %.2f | | |\n", name(c), compressed(plain, c) / n);
    std::printf("| peer: 13-byte codes interleaved, %s | %.2f | | |\n", name(c),
                compressed(interleaved, c) / n);
  }
  for (Compression c : {Compression::kNone, Compression::kZstd, Compression::kLzma2}) {
    std::vector<double> enc, dec;
    std::vector<uint8_t> file;
    for (int r = 0; r < repeats; ++r) {
      auto t = Clock::now();
      file = encode(in, c);
      enc.push_back(ms_since(t));
      t = Clock::now();
      auto reader =
          container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
      auto track = decoder::SurfelsTrack::open(*reader, 1);
      decoder::SurfelBuffer b;
      if (!track.ok() || !track->prototype(0, &b).ok()) std::fprintf(stderr, "decode failed\n");
      dec.push_back(ms_since(t));
    }
    const Spread e = spread(enc), d = spread(dec);
    std::printf("| calf §11.3, %s | %.2f | %.1f (%.1f-%.1f) | %.2f (%.2f-%.2f) |\n", name(c),
                stored_bytes(file) / n, e.median, e.min, e.max, d.median, d.min, d.max);
  }
  // The floor: copying the decoded floats.
  std::vector<float> src(9 * in.size(), 1.0f), dst(src.size());
  std::vector<double> copy;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    std::memcpy(dst.data(), src.data(), 4 * src.size());
    copy.push_back(ms_since(t));
  }
  std::printf("| memcpy of the decoded floats (36 B/surfel) | | | %.3f |\n", spread(copy).median);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-surfels_track_bench: bytes per surfel and coding speed of the surfels track"};
  uint32_t surfels = 100000;
  int repeats = 3;
  app.add_option("--surfels", surfels, "surfels in the buffer")->check(CLI::Range(1u, 1u << 24));
  app.add_option("--repeats", repeats, "runs per figure")->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);
  const auto in = sphere(surfels);
  run("random (as a blue-noise prefix order)", in, repeats);
  run("Morton-sorted (a compressor's best case; not a prefix order)", morton_sorted(in), repeats);
  return 0;
}
