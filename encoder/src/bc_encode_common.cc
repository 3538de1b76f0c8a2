// BCn encoders: shared argument checks, block gathering and threading.
#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "bc_encode_internal.h"

namespace calf::bc {

size_t encode_bound(Format f, uint32_t width, uint32_t height) {
  auto size = compressed_size(f, width, height);
  return size.ok() ? *size : 0;
}

namespace internal {

Status check_image(Format f, const void* pixels, uint32_t width, uint32_t height, size_t row_stride,
                   size_t row_units, uint32_t channels, uint32_t min_channels,
                   uint32_t max_channels, size_t out_size, int quality, int max_quality,
                   int threads) {
  const std::string name = format_name(f);
  CALF_ASSIGN_OR_RETURN(const size_t need, compressed_size(f, width, height));
  if (channels < min_channels || channels > max_channels) {
    return Status(ErrorId::kBcOptions, name + " encoder: " + std::to_string(channels) +
                                           " channels, expected " + std::to_string(min_channels) +
                                           ".." + std::to_string(max_channels));
  }
  if (quality < 0 || quality > max_quality || threads < 0 || threads > 1024) {
    return Status(ErrorId::kBcOptions, name + " encoder: quality " + std::to_string(quality) +
                                           " (0.." + std::to_string(max_quality) + ") or threads " +
                                           std::to_string(threads) + " (0..1024) out of range");
  }
  if (row_stride < size_t{width} * channels) {
    return Status(ErrorId::kBcStride, name + " encoder: row stride " + std::to_string(row_stride) +
                                          " < " + std::to_string(size_t{width} * channels) + " " +
                                          (row_units == 1 ? "bytes" : "floats"));
  }
  if (pixels == nullptr) return Status(ErrorId::kBcBufferSize, name + " encoder: no pixels");
  if (out_size < need) {
    return Status(ErrorId::kBcBufferSize, name + " encoder: output holds " +
                                              std::to_string(out_size) + " bytes, " +
                                              std::to_string(need) + " needed");
  }
  return Status::Ok();
}

void gather8(const Image8& image, uint32_t bx, uint32_t by, uint8_t* rgba) {
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = std::min(bx * 4 + i % 4, image.width - 1);
    const uint32_t y = std::min(by * 4 + i / 4, image.height - 1);
    const uint8_t* p = image.pixels + y * image.row_stride + size_t{x} * image.channels;
    for (uint32_t c = 0; c < 4; ++c)
      rgba[4 * i + c] = c < image.channels ? p[c] : (c == 3 ? 255 : 0);
  }
}

void gatherf(const ImageF& image, uint32_t bx, uint32_t by, float* rgb) {
  for (uint32_t i = 0; i < 16; ++i) {
    const uint32_t x = std::min(bx * 4 + i % 4, image.width - 1);
    const uint32_t y = std::min(by * 4 + i / 4, image.height - 1);
    const float* p = image.pixels + y * image.row_stride + size_t{x} * image.channels;
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = p[c];
  }
}

void run_rows(uint32_t rows, int threads, void (*row)(void*, uint32_t), void* ctx) {
  if (threads == 1 || rows <= 1) {
    for (uint32_t r = 0; r < rows; ++r) row(ctx, r);
    return;
  }
  tbb::task_arena arena(threads == 0 ? tbb::task_arena::automatic : threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, rows),
                      [&](const tbb::blocked_range<uint32_t>& r) {
                        for (uint32_t y = r.begin(); y != r.end(); ++y) row(ctx, y);
                      });
  });
}

}  // namespace internal
}  // namespace calf::bc
