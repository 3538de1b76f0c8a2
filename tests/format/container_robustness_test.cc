// Damage detection and limits: every single-bit change anywhere in a small golden file is
// detected; truncation at every length is "need more data", never a crash; extension is
// corrupt; documented limits hold; codec edge cases; fields and UTF-8 helpers.
#include <gtest/gtest.h>

#include <xxhash.h>

#include <random>

#include "../conformance/container_corpus.h"

namespace calf::container {
namespace {

using corpus::Bytes;

TEST(ContainerRobustnessTest, EverySingleBitFlipIsDetected) {
  for (const Bytes& golden : {*corpus::make_frozen_v1(), *corpus::make_empty()}) {
    ASSERT_TRUE(corpus::first_error(golden).ok());
    // Every offset, one bit each (rotating through the 8 positions); all 8 bits of each byte
    // of the smallest file, whose bytes are all header and directory.
    const int bits = golden.size() < 128 ? 8 : 1;
    for (size_t at = 0; at < golden.size(); ++at) {
      for (int k = 0; k < bits; ++k) {
        Bytes damaged = golden;
        damaged[at] ^= static_cast<uint8_t>(1u << ((at + k) % 8));
        const Status s = corpus::first_error(damaged);
        ASSERT_FALSE(s.ok()) << "bit flip at offset " << at << " went unnoticed";
        EXPECT_NE(s.kind(), ErrorKind::kInternal) << s.to_string();
      }
    }
  }
}

TEST(ContainerRobustnessTest, TruncationAtEveryLengthNeedsMoreData) {
  const Bytes golden = *corpus::make_frozen_v1();
  for (size_t n = 0; n < golden.size(); ++n) {
    const Bytes cut(golden.begin(), golden.begin() + static_cast<std::ptrdiff_t>(n));
    auto r = Reader::open(memory_source(std::span<const uint8_t>(cut)));
    ASSERT_FALSE(r.ok()) << n;
    EXPECT_EQ(r.status().id(), ErrorId::kContainerTruncated) << n << ": " << r.status().to_string();
    EXPECT_EQ(r.status().kind(), ErrorKind::kNeedMoreData);
  }
  Bytes longer = golden;
  longer.push_back(0);
  EXPECT_EQ(corpus::first_error(longer).id(), ErrorId::kContainerFileSize);
}

TEST(ContainerRobustnessTest, MetadataLimits) {
  corpus::Parts p = corpus::take_apart(*corpus::make_empty());
  for (uint32_t i = 0; i <= kMaxMetadataEntries; ++i) {
    char key[16];
    std::snprintf(key, sizeof key, "k%06u", i);
    p.metadata.push_back({key, ""});
  }
  EXPECT_EQ(corpus::first_error(corpus::assemble(p)).id(), ErrorId::kContainerLimit);
  p.metadata.assign({{"a", std::string(kMaxMetadataBytes / 2, 'x')},
                     {"b", std::string(kMaxMetadataBytes / 2, 'y')}});
  EXPECT_EQ(corpus::first_error(corpus::assemble(p)).id(), ErrorId::kContainerLimit);
  p.metadata.assign({{"a", std::string(kMaxMetadataBytes / 2, 'x')}});
  EXPECT_TRUE(corpus::first_error(corpus::assemble(p)).ok());
  p.metadata.assign({{"a", "1"}, {"a", "2"}});  // duplicates are not strictly increasing
  EXPECT_EQ(corpus::first_error(corpus::assemble(p)).id(), ErrorId::kContainerMetadata);
  p.metadata.assign({{std::string("a\0", 2), "1"}});
  EXPECT_EQ(corpus::first_error(corpus::assemble(p)).id(), ErrorId::kContainerMetadata);
}

TEST(ContainerRobustnessTest, LeftoverDirectoryBytesAreCorrupt) {
  corpus::Parts p = corpus::take_apart(*corpus::make_frozen_v1());
  p.tracks[4].header.push_back(0);  // grows an opaque blob: still valid
  EXPECT_TRUE(corpus::first_error(corpus::assemble(p)).ok());
  // Three bytes after the last chunk entry, with sizes and checksums made consistent.
  Bytes file = corpus::assemble(p);
  file.insert(file.end() - 8, {0, 0, 0});
  const uint64_t dir_at = load_le(file.data() + 32, 8);
  const uint64_t dir_size = file.size() - dir_at;
  store_le(file.data() + file.size() - 8,
           hash64(std::span<const uint8_t>(file).subspan(dir_at, dir_size - 8)), 8);
  store_le(file.data() + 24, file.size(), 8);
  store_le(file.data() + 40, dir_size, 8);
  corpus::reseal_header(file);
  const Status s = corpus::first_error(file);
  EXPECT_EQ(s.id(), ErrorId::kContainerDirectoryFormat) << s.to_string();
  EXPECT_NE(s.message().find("3 bytes left over"), std::string::npos) << s.to_string();
}

// A compressed directory (1.1) is any conforming zstd frame: the reader takes one built by hand
// from Raw_Blocks (several of them once the body passes 128 KiB) as it takes the writer's.
TEST(ContainerRobustnessTest, CompressedDirectoryReadsFromAnyConformingFrame) {
  const Bytes written = *corpus::make_frozen_v1(true);
  corpus::Parts p = corpus::take_apart(written);
  ASSERT_EQ(p.header.required_features, kFeatureCompressedDirectory);
  ASSERT_EQ(p.chunks.size(), std::size(corpus::kFrozenSizes));
  const Bytes raw_blocks = corpus::assemble(p);
  EXPECT_NE(raw_blocks, written);
  EXPECT_TRUE(corpus::first_error(raw_blocks).ok()) << corpus::first_error(raw_blocks).to_string();
  p.metadata.push_back({"z.large", std::string(300000, 'q')});  // body of three Raw_Blocks
  const Bytes large = corpus::assemble(p);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(large)));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_GT(r->directory_body_size(), 2u << 17);
  ASSERT_NE(r->find_metadata("z.large"), nullptr);
  EXPECT_EQ(r->find_metadata("z.large")->size(), 300000u);
  for (uint32_t i = 0; i < r->chunks().size(); ++i)
    EXPECT_EQ(*r->read_chunk(i), corpus::pattern(i, corpus::kFrozenSizes[i])) << i;
  EXPECT_TRUE(r->verify().empty());
}

// The writer's two directory forms: the same contents; the plain one is a 1.0 file (minor 0,
// no feature bit), the compressed one a 1.1 file whose directory is smaller than its body.
TEST(ContainerRobustnessTest, WriterDirectoryFormsHoldTheSameContents) {
  const Bytes plain = *corpus::make_frozen_v1(false);
  const Bytes packed = *corpus::make_frozen_v1(true);
  auto a = Reader::open(memory_source(std::span<const uint8_t>(plain)));
  auto b = Reader::open(memory_source(std::span<const uint8_t>(packed)));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->header().version_minor, 0);
  EXPECT_EQ(a->header().required_features, 0u);
  EXPECT_EQ(a->header().directory_size, a->directory_body_size() + 8);
  EXPECT_EQ(b->header().version_minor, 1);
  EXPECT_EQ(b->header().required_features, kFeatureCompressedDirectory);
  EXPECT_EQ(b->directory_body_size(), a->directory_body_size());
  EXPECT_LT(b->header().directory_size, b->directory_body_size());
  EXPECT_EQ(a->header().directory_offset, b->header().directory_offset);  // chunks unchanged
  EXPECT_TRUE(std::equal(plain.begin() + 64,
                         plain.begin() + static_cast<std::ptrdiff_t>(a->header().directory_offset),
                         packed.begin() + 64));
}

TEST(ContainerRobustnessTest, LongerTrackHeadersFromLaterMinorVersionsAreAccepted) {
  corpus::Parts p = corpus::take_apart(*corpus::make_frozen_v1());
  p.tracks[0].header.insert(p.tracks[0].header.end(), {9, 9, 9, 9});
  auto r = Reader::open(memory_source(corpus::assemble(p)));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(std::get<LightfieldTrackHeader>(r->tracks()[0].header).face_size, 128u);
}

TEST(ContainerCodecTest, StoredBoundHoldsAndStreamsMustBeExact) {
  std::mt19937_64 rng(9);
  for (size_t size : {0, 1, 100, 65536, 300000}) {
    Bytes raw(size);
    for (auto& b : raw) b = static_cast<uint8_t>(rng());  // incompressible: worst case
    for (uint16_t c = 0; c < kCompressionCount; ++c) {
      const auto scheme = static_cast<Compression>(c);
      auto stored = compress_chunk(raw, scheme, {1, 0, true, false});  // the scheme asked for
      ASSERT_TRUE(stored.ok()) << stored.status().to_string();
      EXPECT_LE(stored->bytes.size(), stored_bound(size, scheme));
      Bytes out(size);
      ASSERT_TRUE(decompress_chunk(stored->bytes, scheme, out).ok());
      EXPECT_EQ(out, raw);
      if (scheme == Compression::kNone) continue;
      Bytes longer = stored->bytes;
      longer.push_back(0);  // trailing bytes after the stream
      EXPECT_EQ(decompress_chunk(longer, scheme, out).id(), ErrorId::kContainerDecompress);
      Bytes shorter(stored->bytes.begin(), stored->bytes.end() - 1);
      EXPECT_EQ(decompress_chunk(shorter, scheme, out).id(), ErrorId::kContainerDecompress);
      Bytes big(size + 1);  // the stream is shorter than the raw length claimed
      EXPECT_EQ(decompress_chunk(stored->bytes, scheme, big).id(), ErrorId::kContainerDecompress);
      if (size > 0) {
        Bytes small(size - 1);
        EXPECT_EQ(decompress_chunk(stored->bytes, scheme, small).id(),
                  ErrorId::kContainerDecompress);
      }
    }
  }
  Bytes out(1);
  EXPECT_EQ(decompress_chunk({}, Compression::kLzma2, out).id(), ErrorId::kContainerDecompress);
  EXPECT_EQ(decompress_chunk(Bytes{1}, static_cast<Compression>(5), out).id(),
            ErrorId::kContainerCompression);
}

// A zstd frame (RFC 8878) written by hand: magic, Frame_Header_Descriptor `fhd`, the Window
// Descriptor `wd` (when >= 0), a 4-byte Frame_Content_Size, one raw block holding `data`, and
// the content checksum `checksum` when the descriptor's bit 2 asks for one.
Bytes zstd_frame(uint8_t fhd, int wd, const Bytes& data, uint32_t checksum = 0) {
  Bytes f = {0x28, 0xB5, 0x2F, 0xFD, fhd};
  if (wd >= 0) f.push_back(static_cast<uint8_t>(wd));
  f.resize(f.size() + 4);
  store_le(f.data() + f.size() - 4, data.size(), 4);
  f.resize(f.size() + 3);
  store_le(f.data() + f.size() - 3, 1 | (data.size() << 3), 3);  // last block, raw
  f.insert(f.end(), data.begin(), data.end());
  if (fhd & 4) {
    f.resize(f.size() + 4);
    store_le(f.data() + f.size() - 4, checksum, 4);
  }
  return f;
}

// SPEC.md 6.3: Window_Size at most 128 MiB (kMaxZstdWindow, CALF-E049), a regular frame (not
// skippable), a content checksum checked when present.
TEST(ContainerCodecTest, ZstdWindowIsBoundedAndFramesAreRegular) {
  const Bytes data(100, 7);
  Bytes out(data.size());
  constexpr uint8_t kFcs4 = 0x80;  // Frame_Content_Size_flag 2: 4 bytes, no single segment
  // Window_Descriptor: exponent e, mantissa m: 2^(10 + e) * (1 + m / 8).
  EXPECT_TRUE(decompress_chunk(zstd_frame(kFcs4, 17 << 3, data), Compression::kZstd, out).ok());
  EXPECT_EQ(out, data);
  for (int wd : {(17 << 3) | 1, 18 << 3, 21 << 3}) {  // 2^27 + 2^24, 2^28, 2^31
    const Status s = decompress_chunk(zstd_frame(kFcs4, wd, data), Compression::kZstd, out);
    EXPECT_EQ(s.id(), ErrorId::kContainerLimit) << wd << ": " << s.to_string();
    EXPECT_NE(s.message().find("exceeds its limit 134217728"), std::string::npos) << s.message();
  }
  // A single-segment frame's window is its content size.
  const Bytes single = zstd_frame(0xA0, -1, data);
  EXPECT_TRUE(decompress_chunk(single, Compression::kZstd, out).ok());
  // A skippable frame is not a zstd frame with a content size, even for an empty chunk.
  const Bytes skippable = {0x50, 0x2A, 0x4D, 0x18, 4, 0, 0, 0, 1, 2, 3, 4};
  Bytes none;
  EXPECT_EQ(decompress_chunk(skippable, Compression::kZstd, none).id(),
            ErrorId::kContainerDecompress);
  // Content checksums: checked when present (low 32 bits of XXH64 of the content).
  const uint32_t good = static_cast<uint32_t>(XXH64(data.data(), data.size(), 0));
  EXPECT_TRUE(decompress_chunk(zstd_frame(kFcs4 | 4, 0, data, good), Compression::kZstd, out).ok());
  EXPECT_EQ(
      decompress_chunk(zstd_frame(kFcs4 | 4, 0, data, good ^ 1), Compression::kZstd, out).id(),
      ErrorId::kContainerDecompress);
  // Two frames are not one.
  Bytes two = zstd_frame(kFcs4, 0, Bytes(50, 7));
  const Bytes second = two;
  two.insert(two.end(), second.begin(), second.end());
  EXPECT_EQ(decompress_chunk(two, Compression::kZstd, out).id(), ErrorId::kContainerDecompress);
}

TEST(ContainerFieldsTest, DeclaredSizesAndMessages) {
  static_assert(fixed_size<FileHeader>() == 64);
  static_assert(fixed_size<ChunkEntry>() == 64);
  static_assert(fixed_size<LightfieldTrackHeader>() == 36);
  const Bytes blob = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0};  // frame_count, fps_numerator, 2 bytes
  auto h = decode_track_header<LightfieldTrackHeader>(blob, "track 0 (lightfield)");
  ASSERT_FALSE(h.ok());
  EXPECT_EQ(h.status().id(), ErrorId::kContainerTrackHeader);
  EXPECT_NE(h.status().message().find(
                "track 0 (lightfield): fps_denominator needs 4 bytes at offset 8, only 2 left"),
            std::string::npos)
      << h.status().message();
  LightfieldTrackHeader lf;
  lf.face_size = 77;
  auto enc = encode_track_header(lf);
  ASSERT_TRUE(enc.ok());
  EXPECT_EQ(enc->size(), fixed_size<LightfieldTrackHeader>());
  EXPECT_EQ(decode_track_header<LightfieldTrackHeader>(*enc, "")->face_size, 77u);
  const auto printed = print_fields(lf);
  ASSERT_EQ(printed.size(), 11u);
  EXPECT_EQ(printed[4].name, "face_size");
  EXPECT_EQ(printed[4].value, "77");
}

TEST(ContainerFieldsTest, Utf8Validation) {
  EXPECT_TRUE(is_valid_utf8(""));
  EXPECT_TRUE(is_valid_utf8("plain"));
  EXPECT_TRUE(is_valid_utf8("\xc3\xa9\xe2\x9c\x93\xf0\x9f\x90\x84"));
  EXPECT_FALSE(is_valid_utf8("\xc0\xaf"));          // overlong
  EXPECT_FALSE(is_valid_utf8("\xed\xa0\x80"));      // surrogate
  EXPECT_FALSE(is_valid_utf8("\xf4\x90\x80\x80"));  // above U+10FFFF
  EXPECT_FALSE(is_valid_utf8("\xe2\x9c"));          // cut short
  EXPECT_FALSE(is_valid_utf8("\x80"));
}

}  // namespace
}  // namespace calf::container
