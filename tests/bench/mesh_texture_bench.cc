// The mesh track's texture coding (format/SPEC.md §11.4.6) against the alternatives it was chosen
// over, on 8-bit sRGB textures from outside the project (default: the textures of Debian's
// assimp-testmodels glTF samples). Per texture: the raw RGBA8 bytes; the raw bytes supercompressed
// whole (zstd -19, LZMA2 preset 6: calf's coding 1, plain texels); calf's MED channel planes
// (coding 0) with the same two (the encoder keeps the smaller of the two codings); and BC7 (quality
// 1) and BC1 (range fit) blocks of the whole mip chain (what a GPU-ready track would store), zstd
// -19 on top, with the PSNR of their level 0 against the texture (RGB, sRGB bytes) and of the mip
// chain's levels 1.. against calf's derived levels. Also the time to decode the MED planes (median
// of --repeats) beside a memcpy.
//
//   bench-mesh_texture_bench [--repeats 5] [FILE.png ...]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <CLI/CLI.hpp>

#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"
#include "calf/format/container_codec.h"
#include "calf/format/mesh_layout.h"
#include "calf/format/mesh_texture.h"

namespace {

using namespace calf;
using Clock = std::chrono::steady_clock;

bool load(const std::string& path, mesh::TextureTexels* t) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return false;
  const OIIO::ImageSpec& spec = in->spec();
  t->width = static_cast<uint32_t>(spec.width);
  t->height = static_cast<uint32_t>(spec.height);
  std::vector<uint8_t> pixels(size_t{t->width} * t->height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, pixels.data())) return false;
  t->rgba.assign(size_t{t->width} * t->height * 4, 255);
  for (size_t i = 0; i < size_t{t->width} * t->height; ++i) {
    for (int c = 0; c < 4; ++c) {
      if (c < spec.nchannels)
        t->rgba[4 * i + c] = pixels[i * spec.nchannels + std::min(c, 3)];
      else if (c < 3)
        t->rgba[4 * i + c] = pixels[i * spec.nchannels];  // grey
    }
  }
  return true;
}

size_t stored(const std::vector<uint8_t>& raw, container::Compression c) {
  auto s = container::compress_chunk(raw, c, {});
  return s.ok() ? s->bytes.size() : 0;
}

// PSNR of RGB bytes.
double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    se += d * d;
    ++n;
  }
  return se == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * n / se);
}

struct BcResult {
  size_t raw = 0, zstd = 0;
  double psnr0 = 0, psnr_mips = 0;
};

BcResult bc_chain(const std::vector<mesh::TextureTexels>& chain, bc::Format f) {
  BcResult r;
  std::vector<uint8_t> all;
  double se_mips = 0;
  size_t n_mips = 0;
  for (size_t k = 0; k < chain.size(); ++k) {
    const auto& l = chain[k];
    const size_t size = bc::encode_bound(f, l.width, l.height);
    std::vector<uint8_t> blocks(size);
    bc::Image8 im{l.rgba.data(), l.width, l.height, size_t{l.width} * 4, 4};
    const Status st = f == bc::Format::kBc7
                          ? bc::encode_bc7(im, blocks.data(), size, {1, 0})
                          : bc::encode_bc1(im, blocks.data(), size, {0, false, 0});
    if (!st.ok()) return r;
    std::vector<uint8_t> back(l.rgba.size());
    if (!bc::decode_image(f, blocks.data(), size, l.width, l.height, back.data(), back.size(),
                          size_t{l.width} * 4)
             .ok())
      return r;
    if (k == 0) {
      r.psnr0 = psnr(l.rgba, back);
    } else {
      for (size_t i = 0; i < back.size(); ++i) {
        if (i % 4 == 3) continue;
        const double d = static_cast<double>(back[i]) - static_cast<double>(l.rgba[i]);
        se_mips += d * d;
        ++n_mips;
      }
    }
    all.insert(all.end(), blocks.begin(), blocks.end());
  }
  r.raw = all.size();
  r.zstd = stored(all, container::Compression::kZstd);
  r.psnr_mips = se_mips == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * n_mips / se_mips);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The mesh track's texture coding against plain and BCn textures (SPEC 11.4.6)."};
  int repeats = 5;
  std::vector<std::string> files = {
      "/usr/share/assimp/models/glTF/CesiumMilkTruck/CesiumMilkTruck.png",
      "/usr/share/assimp/models/glTF2/BoxTextured-glTF/CesiumLogoFlat.png"};
  app.add_option("--repeats", repeats, "timed repeats (median reported)")->capture_default_str();
  app.add_option("FILES", files, "8-bit textures (default: two assimp-testmodels textures)");
  CLI11_PARSE(app, argc, argv);
  std::printf("%-30s %9s | %8s %8s | %8s %8s | %9s %8s %6s %6s | %8s %6s | %8s %8s\n", "texture",
              "RGBA8", "raw+zstd", "raw+lzma", "MED+zstd", "MED+lzma", "BC7 mips", "+zstd", "dB L0",
              "dB mip", "BC1+zstd", "dB L0", "MED dec", "memcpy");
  for (const std::string& path : files) {
    mesh::TextureTexels t;
    if (!load(path, &t)) {
      std::fprintf(stderr, "%s: cannot read\n", path.c_str());
      return 1;
    }
    const mesh::TextureRecord record{t.width, t.height};
    const std::vector<uint8_t> med = *mesh::encode_texture(record, t);

    const auto chain = mesh::mip_chain(t);
    const BcResult bc7 = bc_chain(chain, bc::Format::kBc7);
    const BcResult bc1 = bc_chain(chain, bc::Format::kBc1);
    std::vector<double> dec, copy;
    mesh::TextureTexels back;
    std::vector<uint8_t> sink(t.rgba.size());
    for (int r = 0; r < repeats; ++r) {
      auto t0 = Clock::now();
      (void)mesh::decode_texture(med, record, &back, "bench");
      dec.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      t0 = Clock::now();
      std::memcpy(sink.data(), t.rgba.data(), sink.size());
      copy.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    std::sort(dec.begin(), dec.end());
    std::sort(copy.begin(), copy.end());
    if (back.rgba != t.rgba) std::fprintf(stderr, "%s: MED round trip differs\n", path.c_str());
    const std::string name = path.substr(path.find_last_of('/') + 1);
    std::printf(
        "%-30s %9zu | %8zu %8zu | %8zu %8zu | %9zu %8zu %6.2f %6.2f | %8zu %6.2f | "
        "%6.2fms %6.3fms\n",
        (name + " " + std::to_string(t.width) + "x" + std::to_string(t.height)).c_str(),
        t.rgba.size(), stored(t.rgba, container::Compression::kZstd),
        stored(t.rgba, container::Compression::kLzma2), stored(med, container::Compression::kZstd),
        stored(med, container::Compression::kLzma2), bc7.raw, bc7.zstd, bc7.psnr0, bc7.psnr_mips,
        bc1.zstd, bc1.psnr0, dec[dec.size() / 2], copy[copy.size() / 2]);
  }
  return 0;
}
