// What closed colour segments cost (docs/FARM.md, `--segment-frames`): encodes a capture set with
// each segment length (0 = none), decodes every face of every frame with the reference decoder
// and prints the clip's bytes, colour keyframes and colour PSNR against the capture (log2-PSNR,
// 8-stop peak, for HDR; sRGB PSNR for LDR: the encoder's metrics) and against the unsegmented
// clip. Usage: bench-segment_cost --capture DIR --segments 0,4,8 [--keyframe-interval K]
#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/capture/capture_set.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/encoder/colour_keyframes.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"

namespace {

struct Result {
  uint64_t bytes = 0, keyframes = 0;
  double seconds = 0;
  std::vector<std::vector<float>> faces;  // decoded colour, [view][frame][face]
};

bool encode_and_decode(const calf::capture::CaptureSetReader& input,
                       calf::encoder::LightfieldEncodeOptions o, Result* r) {
  std::vector<uint8_t> bytes;
  auto writer = calf::container::Writer::create(calf::container::memory_sink(&bytes));
  if (!writer.ok()) return false;
  const auto t0 = std::chrono::steady_clock::now();
  auto stats = calf::encoder::encode_lightfield(input, *writer, o);
  if (!stats.ok() || !writer->finish().ok()) {
    std::fprintf(stderr, "encode: %s\n", stats.status().to_string().c_str());
    return false;
  }
  r->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r->bytes = bytes.size();
  r->keyframes = stats->colour_keyframes;
  auto reader = calf::container::Reader::open(calf::container::memory_source(std::move(bytes)));
  if (!reader.ok()) return false;
  auto dec = calf::decoder::LightfieldReference::open(*reader, 0);
  if (!dec.ok()) {
    std::fprintf(stderr, "decode: %s\n", dec.status().to_string().c_str());
    return false;
  }
  const auto& m = input.manifest();
  calf::decoder::LightfieldFace face;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      for (uint32_t k = 0; k < 6; ++k) {
        if (calf::Status s = dec->decode_face(v, k, f, &face); !s.ok()) {
          std::fprintf(stderr, "decode: %s\n", s.to_string().c_str());
          return false;
        }
        r->faces.push_back(face.colour);
      }
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-segment_cost: bytes and PSNR of closed colour segments"};
  std::string capture_dir, segments_text = "0,4,8";
  uint32_t k = 4, threads = 2;
  app.add_option("--capture", capture_dir, "capture set directory")->required();
  app.add_option("--segments", segments_text, "segment lengths, 0 = none (default 0,4,8)");
  app.add_option("--keyframe-interval", k, "depth keyframe interval K for every run (default 4)");
  app.add_option("--threads", threads, "encode threads (default 2)");
  CLI11_PARSE(app, argc, argv);
  auto input = calf::capture::CaptureSetReader::open(capture_dir);
  if (!input.ok()) {
    std::fprintf(stderr, "%s\n", input.status().to_string().c_str());
    return 1;
  }
  const auto& m = input->manifest();
  // The capture's colour per view, frame, face (the reference of every PSNR).
  std::vector<std::vector<float>> source;
  calf::capture::ViewFrame vf;
  bool hdr = false;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      if (!input->read(v, f, &vf).ok()) return 1;
      const size_t n = size_t{m.face_size} * m.face_size * 3;
      for (uint32_t face = 0; face < 6; ++face) {
        source.emplace_back(vf.color.begin() + face * n, vf.color.begin() + (face + 1) * n);
        for (float c : source.back()) hdr = hdr || c > 1.0f;
      }
    }
  }
  auto psnr = [&](const std::vector<std::vector<float>>& a,
                  const std::vector<std::vector<float>>& b) {
    std::vector<float> x, y;
    for (size_t i = 0; i < a.size(); ++i) {
      x.insert(x.end(), a[i].begin(), a[i].end());
      y.insert(y.end(), b[i].begin(), b[i].end());
    }
    return hdr ? calf::encoder::psnr_log2(x, y) : calf::encoder::psnr_srgb(x, y);
  };
  std::printf("capture %s: %zu views x %u frames, face %u, %s, depth K %u\n\n", capture_dir.c_str(),
              m.viewpoints.size(), m.frame_count, m.face_size,
              hdr ? "HDR (log2-PSNR, 8-stop peak)" : "LDR (sRGB PSNR)", k);
  std::printf(
      "| --segment-frames | clip bytes | vs none | colour keyframes | PSNR vs capture dB | "
      "PSNR vs unsegmented dB | encode s |\n|---:|---:|---:|---:|---:|---:|---:|\n");
  std::stringstream list(segments_text);
  std::string item;
  Result none;
  bool have_none = false;
  while (std::getline(list, item, ',')) {
    calf::encoder::LightfieldEncodeOptions o;
    o.threads = threads;
    o.depth_keyframe_interval = k;
    o.segment_frames = static_cast<uint32_t>(std::stoul(item));
    Result r;
    if (!encode_and_decode(*input, o, &r)) return 1;
    if (o.segment_frames == 0) {
      none = r;
      have_none = true;
    }
    std::printf(
        "| %s | %llu | %s | %llu | %.2f | %s | %.2f |\n",
        o.segment_frames ? item.c_str() : "none (0)", static_cast<unsigned long long>(r.bytes),
        have_none ? (std::to_string(static_cast<double>(r.bytes) / static_cast<double>(none.bytes))
                         .substr(0, 5) +
                     "x")
                        .c_str()
                  : "-",
        static_cast<unsigned long long>(r.keyframes), psnr(source, r.faces),
        have_none ? std::to_string(psnr(none.faces, r.faces)).c_str() : "-", r.seconds);
  }
  return 0;
}
