// Hashing and supercompression of container chunks. See container_codec.h for the stored forms.
#include "calf/format/container_codec.h"

#include <lzma.h>
#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <memory>
#include <optional>

namespace calf::container {
namespace {

// The largest zstd Window_Size a reader accepts (SPEC.md 6.3, "Limits"): libzstd's default for
// streaming decoders, and the largest window of any of its compression levels.
constexpr uint64_t kMaxZstdWindow = uint64_t{1} << 27;

struct ZstdCCtxDeleter {
  void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
};
struct ZstdDCtxDeleter {
  void operator()(ZSTD_DCtx* d) const { ZSTD_freeDCtx(d); }
};

// Dictionary for an LZMA2 chunk: the preset's, shrunk to the chunk (a bigger one only costs the
// decoder memory), never below liblzma's 4 KiB minimum. Depends only on the preset and the raw
// size, so the stored bytes stay deterministic.
uint32_t lzma_dictionary_for(uint64_t raw_size, uint32_t preset_dict) {
  uint64_t dict = std::min<uint64_t>(preset_dict, std::max<uint64_t>(raw_size, LZMA_DICT_SIZE_MIN));
  return static_cast<uint32_t>(std::max<uint64_t>(dict, LZMA_DICT_SIZE_MIN));
}

Expected<StoredChunk> compress_zstd(std::span<const uint8_t> raw, int level) {
  std::unique_ptr<ZSTD_CCtx, ZstdCCtxDeleter> cctx(ZSTD_createCCtx());
  if (!cctx) return Status(ErrorId::kContainerCompressor, "zstd: cannot create a context");
  // Single-threaded, content size recorded, no zstd checksum or dictionary id: the stored form
  // of SPEC.md, identical whatever the caller's threading.
  const size_t params[][2] = {{ZSTD_c_compressionLevel, static_cast<size_t>(level)},
                              {ZSTD_c_contentSizeFlag, 1},
                              {ZSTD_c_checksumFlag, 0},
                              {ZSTD_c_dictIDFlag, 0},
                              {ZSTD_c_nbWorkers, 0}};
  for (const auto& p : params) {
    const size_t r = ZSTD_CCtx_setParameter(cctx.get(), static_cast<ZSTD_cParameter>(p[0]),
                                            static_cast<int>(p[1]));
    if (ZSTD_isError(r))
      return Status(ErrorId::kContainerCompressor, cat("zstd: ", ZSTD_getErrorName(r)));
  }
  StoredChunk out{Compression::kZstd, raw.size(), {}};
  out.bytes.resize(ZSTD_compressBound(raw.size()));
  const size_t n =
      ZSTD_compress2(cctx.get(), out.bytes.data(), out.bytes.size(), raw.data(), raw.size());
  if (ZSTD_isError(n))
    return Status(ErrorId::kContainerCompressor, cat("zstd: ", ZSTD_getErrorName(n)));
  // The bound's capacity is released: a writer may hold several chunks before it stores them.
  out.bytes.resize(n);
  out.bytes.shrink_to_fit();
  return out;
}

Expected<StoredChunk> compress_lzma2(std::span<const uint8_t> raw, uint32_t preset) {
  lzma_options_lzma opt;
  if (lzma_lzma_preset(&opt, preset))
    return Status(ErrorId::kContainerWriterMisuse, cat("lzma preset ", preset, " is invalid"));
  opt.dict_size = lzma_dictionary_for(raw.size(), opt.dict_size);
  lzma_filter filters[2] = {{LZMA_FILTER_LZMA2, &opt}, {LZMA_VLI_UNKNOWN, nullptr}};
  uint8_t prop = 0;
  if (lzma_properties_encode(&filters[0], &prop) != LZMA_OK)
    return Status(ErrorId::kContainerCompressor, "lzma: cannot encode the filter properties");
  StoredChunk out{Compression::kLzma2, raw.size(), {}};
  out.bytes.resize(stored_bound(raw.size(), Compression::kLzma2));
  out.bytes[0] = prop;
  size_t pos = 1;
  const lzma_ret r = lzma_raw_buffer_encode(filters, nullptr, raw.data(), raw.size(),
                                            out.bytes.data(), &pos, out.bytes.size());
  if (r != LZMA_OK) return Status(ErrorId::kContainerCompressor, cat("lzma: error ", int(r)));
  out.bytes.resize(pos);
  out.bytes.shrink_to_fit();
  return out;
}

// The Window_Size of the zstd frame `stored` starts with (RFC 8878 3.1.1.1.2; a single-segment
// frame's window is its Frame_Content_Size), or nullopt unless `stored` starts with the header of
// a regular zstd frame (magic 0xFD2FB528: not a skippable or legacy frame).
std::optional<uint64_t> zstd_window_size(std::span<const uint8_t> stored) {
  if (stored.size() < 6 || load_le(stored.data(), 4) != 0xFD2FB528u) return std::nullopt;
  const uint8_t descriptor = stored[4];
  if ((descriptor & 0x20) == 0) {  // Single_Segment_flag clear: a Window_Descriptor follows
    const uint8_t w = stored[5];
    const uint64_t base = uint64_t{1} << (10 + (w >> 3));
    return base + (base / 8) * (w & 7);
  }
  // Frame_Content_Size after the Dictionary_ID field (0, 1, 2 or 4 bytes): 1, 2 (+256), 4 or 8.
  static constexpr size_t kDidBytes[4] = {0, 1, 2, 4}, kFcsBytes[4] = {1, 2, 4, 8};
  const size_t at = 5 + kDidBytes[descriptor & 3], n = kFcsBytes[descriptor >> 6];
  if (stored.size() < at + n) return std::nullopt;
  return load_le(stored.data() + at, n) + (n == 2 ? 256 : 0);
}

Status decompress_zstd(std::span<const uint8_t> stored, std::span<uint8_t> out) {
  // The window a decoder that decodes in pieces must keep, bounded (SPEC.md 6.3) so that every
  // conforming reader can decode every chunk; libzstd's one-shot decoding would accept up to 2 GiB.
  const std::optional<uint64_t> window = zstd_window_size(stored);
  if (!window)
    return Status(ErrorId::kContainerDecompress, "stored bytes do not start with a zstd frame");
  if (*window > kMaxZstdWindow)
    return Status(ErrorId::kContainerLimit,
                  cat("zstd window of ", *window, " bytes exceeds its limit ", kMaxZstdWindow));
  // Check the frame's own size claims before decoding: exactly one frame, spanning all stored
  // bytes, declaring the raw length.
  const size_t frame = ZSTD_findFrameCompressedSize(stored.data(), stored.size());
  if (ZSTD_isError(frame) || frame != stored.size())
    return Status(ErrorId::kContainerDecompress,
                  cat("zstd frame is not exactly the ", stored.size(), " stored bytes"));
  const unsigned long long content = ZSTD_getFrameContentSize(stored.data(), stored.size());
  if (content != out.size())
    return Status(
        ErrorId::kContainerDecompress,
        cat("zstd frame declares ",
            content == ZSTD_CONTENTSIZE_UNKNOWN ? std::string("no") : std::to_string(content),
            " content bytes, raw length is ", out.size()));
  // One context per thread, reused: creating one costs more than decoding a small chunk (it was
  // a third of a view-dependent decoder's frame time).
  thread_local std::unique_ptr<ZSTD_DCtx, ZstdDCtxDeleter> dctx(ZSTD_createDCtx());
  if (!dctx) return Status(ErrorId::kContainerCompressor, "zstd: cannot create a context");
  const size_t n =
      ZSTD_decompressDCtx(dctx.get(), out.data(), out.size(), stored.data(), stored.size());
  if (ZSTD_isError(n))
    return Status(ErrorId::kContainerDecompress, cat("zstd: ", ZSTD_getErrorName(n)));
  if (n != out.size())
    return Status(ErrorId::kContainerDecompress,
                  cat("zstd produced ", n, " bytes, raw length is ", out.size()));
  return Status::Ok();
}

Status decompress_lzma2(std::span<const uint8_t> stored, std::span<uint8_t> out) {
  if (stored.empty())
    return Status(ErrorId::kContainerDecompress, "LZMA2 chunk lacks its property byte");
  lzma_filter filters[2] = {{LZMA_FILTER_LZMA2, nullptr}, {LZMA_VLI_UNKNOWN, nullptr}};
  if (lzma_properties_decode(&filters[0], nullptr, stored.data(), 1) != LZMA_OK)
    return Status(ErrorId::kContainerDecompress,
                  cat("LZMA2 property byte ", stored[0], " is invalid"));
  // liblzma allocated the options; own them before any early return.
  std::unique_ptr<lzma_options_lzma, void (*)(void*)> opt(
      static_cast<lzma_options_lzma*>(filters[0].options), free);
  // The decoder allocates the whole dictionary: refuse a hostile one before it does.
  if (opt->dict_size > kMaxLzmaDictionary)
    return Status(ErrorId::kContainerLimit, cat("LZMA2 dictionary ", opt->dict_size,
                                                " exceeds its limit ", kMaxLzmaDictionary));
  size_t in_pos = 1, out_pos = 0;
  // liblzma refuses an empty output buffer; an empty chunk decodes into a spare byte that any
  // decoded data would overflow (caught below as out_pos != 0).
  uint8_t spare = 0;
  uint8_t* dst = out.empty() ? &spare : out.data();
  const size_t dst_size = out.empty() ? 1 : out.size();
  const lzma_ret r = lzma_raw_buffer_decode(filters, nullptr, stored.data(), &in_pos, stored.size(),
                                            dst, &out_pos, dst_size);
  if (r != LZMA_OK)
    return Status(ErrorId::kContainerDecompress,
                  cat("LZMA2 stream is invalid or longer than the raw length ", out.size(),
                      " (liblzma error ", int(r), ")"));
  if (out_pos != out.size() || in_pos != stored.size())
    return Status(ErrorId::kContainerDecompress,
                  cat("LZMA2 stream decoded ", out_pos, " of ", out.size(), " raw bytes from ",
                      in_pos, " of ", stored.size(), " stored bytes"));
  return Status::Ok();
}

}  // namespace

uint64_t hash64(std::span<const uint8_t> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

uint64_t stored_bound(uint64_t raw_size, Compression c) {
  switch (c) {
    case Compression::kNone:
      return raw_size;
    case Compression::kZstd:
      return ZSTD_COMPRESSBOUND(raw_size);
    case Compression::kLzma2:
      // lzma_block_buffer_bound covers LZMA2 plus .xz block framing; +1 for our property byte.
      return 1 + lzma_block_buffer_bound(static_cast<size_t>(raw_size));
  }
  return 0;
}

Expected<StoredChunk> compress_chunk(std::span<const uint8_t> raw, Compression c,
                                     const CompressionOptions& options) {
  // The raw bytes themselves where the compressed frame is no smaller (and the options allow).
  auto keep_smaller = [&](Expected<StoredChunk> packed) -> Expected<StoredChunk> {
    if (!packed.ok() || !options.store_when_larger || packed->bytes.size() < raw.size()) {
      return packed;
    }
    return StoredChunk{Compression::kNone, raw.size(),
                       std::vector<uint8_t>(raw.begin(), raw.end())};
  };
  if (raw.size() > kMaxRawChunkSize)
    return Status(ErrorId::kContainerWriterMisuse,
                  cat("raw chunk of ", raw.size(), " bytes exceeds the limit ", kMaxRawChunkSize));
  switch (c) {
    case Compression::kNone:
      return StoredChunk{c, raw.size(), std::vector<uint8_t>(raw.begin(), raw.end())};
    case Compression::kZstd:
      if (options.zstd_level < 1 || options.zstd_level > ZSTD_maxCLevel())
        return Status(
            ErrorId::kContainerWriterMisuse,
            cat("zstd level ", options.zstd_level, " is outside [1, ", ZSTD_maxCLevel(), "]"));
      return keep_smaller(compress_zstd(raw, options.zstd_level));
    case Compression::kLzma2:
      return keep_smaller(compress_lzma2(raw, options.lzma_preset));
  }
  return Status(ErrorId::kContainerWriterMisuse,
                cat("supercompression ", static_cast<unsigned>(c), " is unknown"));
}

Status decompress_chunk(std::span<const uint8_t> stored, Compression c, std::span<uint8_t> out) {
  switch (c) {
    case Compression::kNone:
      if (stored.size() != out.size())
        return Status(ErrorId::kContainerDecompress, cat("stored length ", stored.size(),
                                                         " differs from raw length ", out.size()));
      std::copy(stored.begin(), stored.end(), out.begin());
      return Status::Ok();
    case Compression::kZstd:
      return decompress_zstd(stored, out);
    case Compression::kLzma2:
      return decompress_lzma2(stored, out);
  }
  return Status(ErrorId::kContainerCompression,
                cat("supercompression ", static_cast<unsigned>(c), " is unknown"));
}

}  // namespace calf::container
