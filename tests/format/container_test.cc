// Container writer/reader round trips, determinism, API contracts and the byte-counting proof
// that reading one chunk touches only the header, the directory and that chunk.
#include "calf/format/container.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

namespace calf::container {
namespace {

using Bytes = std::vector<uint8_t>;

// Random content with some redundancy, so compression has something to find.
Bytes random_bytes(std::mt19937_64& rng, size_t n) {
  Bytes b(n);
  const int period = 1 + static_cast<int>(rng() % 64);
  for (size_t i = 0; i < n; ++i)
    b[i] = (rng() % 4 == 0) ? static_cast<uint8_t>(rng()) : static_cast<uint8_t>(i % period);
  return b;
}

struct Clip {
  Bytes file;
  std::vector<Bytes> raws;
  std::vector<ChunkKeys> keys;
  std::vector<Compression> compressions;
};

// A clip with one lightfield track, one unknown optional track and `n` random chunks, each stored
// with the scheme asked for (random bytes do not compress: store_when_larger would store them raw).
Clip make_clip(uint64_t seed, int n, const CompressionOptions& opt = {1, 0, true, false}) {
  std::mt19937_64 rng(seed);
  Clip clip;
  auto w = Writer::create(memory_sink(&clip.file), opt);
  EXPECT_TRUE(w.ok()) << w.status().to_string();
  LightfieldTrackHeader lf;
  lf.frame_count = 30;
  lf.view_count = 4;
  lf.face_size = 256;
  lf.cell_size = 64;
  lf.depth_region_size = 128;
  lf.colour_format = static_cast<uint16_t>(PixelFormat::kBc7);
  EXPECT_TRUE(w->add_track(lf).ok());
  EXPECT_TRUE(w->add_track(999, 0, Bytes{1, 2, 3}).ok());  // an unknown optional track
  EXPECT_TRUE(w->set_metadata("title", "caf\xc3\xa9 \xe2\x9c\x93").ok());
  EXPECT_TRUE(w->set_metadata("encoder", "test").ok());
  for (int i = 0; i < n; ++i) {
    const size_t size = rng() % 4 == 0 ? 0 : rng() % 3000;
    clip.raws.push_back(random_bytes(rng, size));
    ChunkKeys k;
    k.track = static_cast<uint16_t>(rng() % 2);
    k.stream = static_cast<uint16_t>(rng() % 5);
    k.view = static_cast<uint32_t>(rng() % 4);
    k.face = static_cast<uint32_t>(rng() % 6);
    k.region = static_cast<uint32_t>(rng());
    k.layer = static_cast<uint32_t>(rng() % 3);
    k.first_frame = static_cast<uint32_t>(rng() % 30);
    k.frame_count = static_cast<uint32_t>(rng() % 5);
    clip.keys.push_back(k);
    clip.compressions.push_back(static_cast<Compression>(rng() % 3));
    auto id = w->add_chunk(k, clip.raws.back(), clip.compressions.back());
    EXPECT_TRUE(id.ok()) << id.status().to_string();
    EXPECT_EQ(*id, static_cast<uint32_t>(i));
  }
  EXPECT_TRUE(w->finish().ok());
  return clip;
}

// CompressionOptions::store_when_larger (the default): a chunk zstd or LZMA2 would not shrink is
// stored raw, one they shrink keeps its scheme; false keeps the scheme asked for. Either way the
// chunk reads back as written, and the 1.1 directory stays one zstd frame however small.
TEST(ContainerTest, ChunksThatCompressionWouldEnlargeAreStoredRaw) {
  std::mt19937_64 rng(5);
  Bytes noise(3000);
  for (auto& b : noise) b = static_cast<uint8_t>(rng());  // white noise: no scheme shrinks it
  const Bytes zeros(3000, 0), tiny{7};
  for (bool store_raw : {true, false}) {
    for (Compression c : {Compression::kZstd, Compression::kLzma2}) {
      CompressionOptions opt;
      opt.store_when_larger = store_raw;
      Bytes file;
      auto w = Writer::create(memory_sink(&file), opt);
      ASSERT_TRUE(w.ok());
      ASSERT_TRUE(w->add_track(999, 0, Bytes{1}).ok());
      ChunkKeys k;
      for (const Bytes* raw : {static_cast<const Bytes*>(&noise), &zeros, &tiny}) {
        ASSERT_TRUE(w->add_chunk(k, *raw, c).ok());
        ++k.region;
      }
      ASSERT_TRUE(w->finish().ok());
      auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
      ASSERT_TRUE(r.ok()) << r.status().to_string();
      const uint16_t asked = static_cast<uint16_t>(c), none = 0;
      EXPECT_EQ(r->chunks()[0].compression, store_raw ? none : asked);
      if (store_raw) {
        EXPECT_EQ(r->chunks()[0].stored_size, noise.size());
      } else {
        EXPECT_GT(r->chunks()[0].stored_size, noise.size());  // what store_when_larger avoids
      }
      EXPECT_EQ(r->chunks()[1].compression, asked);
      EXPECT_LT(r->chunks()[1].stored_size, zeros.size());
      EXPECT_EQ(r->chunks()[2].compression, store_raw ? none : asked);
      EXPECT_EQ(*r->read_chunk(0), noise);
      EXPECT_EQ(*r->read_chunk(1), zeros);
      EXPECT_EQ(*r->read_chunk(2), tiny);
      EXPECT_TRUE(r->verify().empty());
    }
  }
  // A directory zstd does not shrink is still written as one zstd frame, which is what a 1.1
  // reader requires: one track whose header is white noise and no chunk, so the directory body
  // is nearly all noise.
  Bytes file;
  auto w = Writer::create(memory_sink(&file), CompressionOptions{});
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(w->add_track(999, 0, noise).ok());
  ASSERT_TRUE(w->finish().ok());
  auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->tracks().size(), 1u);
}

TEST(ContainerTest, RoundTripsRandomContentsAndCompressions) {
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const Clip clip = make_clip(seed, 25);
    auto r = Reader::open(memory_source(std::span<const uint8_t>(clip.file)));
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    ASSERT_EQ(r->chunks().size(), clip.raws.size());
    for (uint32_t i = 0; i < clip.raws.size(); ++i) {
      auto raw = r->read_chunk(i);
      ASSERT_TRUE(raw.ok()) << raw.status().to_string();
      EXPECT_EQ(*raw, clip.raws[i]);
      EXPECT_EQ(r->chunks()[i].keys, clip.keys[i]);
      EXPECT_EQ(r->chunks()[i].compression, static_cast<uint16_t>(clip.compressions[i]));
      EXPECT_EQ(r->chunks()[i].offset % kAlignment, 0u);
    }
    EXPECT_TRUE(r->verify().empty());
    ASSERT_EQ(r->tracks().size(), 2u);
    EXPECT_TRUE(r->tracks()[0].known);
    EXPECT_EQ(std::get<LightfieldTrackHeader>(r->tracks()[0].header).face_size, 256u);
    EXPECT_FALSE(r->tracks()[1].known);  // unknown optional track: skipped, not refused
    EXPECT_EQ(r->tracks()[1].record.header, (Bytes{1, 2, 3}));
    ASSERT_NE(r->find_metadata("title"), nullptr);
    EXPECT_EQ(*r->find_metadata("title"), "caf\xc3\xa9 \xe2\x9c\x93");
    EXPECT_EQ(r->metadata()[0].key, "encoder");  // sorted, whatever the call order
    EXPECT_EQ(r->find_metadata("nope"), nullptr);
  }
}

TEST(ContainerTest, WritingTwiceGivesIdenticalBytes) {
  const CompressionOptions opt{19, 6};
  EXPECT_EQ(make_clip(7, 20, opt).file, make_clip(7, 20, opt).file);
  EXPECT_EQ(make_clip(8, 0).file, make_clip(8, 0).file);
}

TEST(ContainerTest, ParallelCompressionGivesTheSameBytes) {
  // Chunks compressed out of order (as worker threads would) and added in order.
  std::mt19937_64 rng(3);
  std::vector<Bytes> raws;
  for (int i = 0; i < 8; ++i) raws.push_back(random_bytes(rng, 5000));
  auto write = [&](bool reversed) {
    std::vector<StoredChunk> stored(raws.size());
    for (size_t k = 0; k < raws.size(); ++k) {
      const size_t i = reversed ? raws.size() - 1 - k : k;
      stored[i] = *compress_chunk(raws[i], i % 2 ? Compression::kZstd : Compression::kLzma2);
    }
    Bytes file;
    auto w = Writer::create(memory_sink(&file));
    EXPECT_TRUE(w->add_track(LightfieldTrackHeader{}).ok());
    for (const auto& s : stored) EXPECT_TRUE(w->add_stored_chunk({}, s).ok());
    EXPECT_TRUE(w->finish().ok());
    return file;
  };
  EXPECT_EQ(write(false), write(true));
}

TEST(ContainerTest, FindChunksFiltersByKeys) {
  const Clip clip = make_clip(11, 40);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(clip.file)));
  ASSERT_TRUE(r.ok());
  ChunkQuery q;
  q.track = 0;
  q.view = 2;
  q.frame = 5;
  const auto ids = r->find_chunks(q);
  for (uint32_t i = 0; i < clip.keys.size(); ++i) {
    const auto& k = clip.keys[i];
    const bool match = k.track == 0 && k.view == 2 && k.first_frame <= 5 &&
                       5 < uint64_t{k.first_frame} + k.frame_count;
    EXPECT_EQ(std::count(ids.begin(), ids.end(), i), match ? 1 : 0) << i;
  }
  EXPECT_EQ(r->find_chunks({}).size(), clip.keys.size());
}

TEST(ContainerTest, CallerBuffersAndIds) {
  const Clip clip = make_clip(12, 5);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(clip.file)));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->read_chunk(5).status().id(), ErrorId::kContainerChunkId);
  EXPECT_EQ(r->read_stored(99).status().id(), ErrorId::kContainerChunkId);
  Bytes wrong(r->chunks()[0].raw_size + 1);
  EXPECT_EQ(r->read_chunk_into(0, wrong).id(), ErrorId::kContainerBufferSize);
  std::vector<uint8_t> scratch;
  for (uint32_t i = 0; i < 5; ++i) {
    Bytes out(r->chunks()[i].raw_size);
    ASSERT_TRUE(r->read_chunk_into(i, out, scratch).ok());
    EXPECT_EQ(out, clip.raws[i]);
  }
}

TEST(ContainerTest, WriterRefusesWhatReadersWouldReject) {
  Bytes file;
  auto w = Writer::create(memory_sink(&file));
  ASSERT_TRUE(w.ok());
  LightfieldTrackHeader lf;
  lf.face_size = 0;
  EXPECT_EQ(w->add_track(lf).status().id(), ErrorId::kContainerWriterMisuse);
  lf.face_size = kMaxDimension + 1;
  EXPECT_EQ(w->add_track(lf).status().id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->add_track(0, 0, {}).status().id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->add_chunk({}, Bytes{1}, Compression::kNone).status().id(),
            ErrorId::kContainerWriterMisuse);  // no track 0 yet
  EXPECT_EQ(w->set_metadata("", "x").id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->set_metadata(std::string("a\0b", 3), "x").id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->set_metadata("k", "\xff").id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->set_metadata(std::string(kMaxMetadataKeySize + 1, 'k'), "").id(),
            ErrorId::kContainerWriterMisuse);
  ASSERT_TRUE(w->add_track(TilesTrackHeader{}).ok());
  StoredChunk bad{Compression::kNone, 5, Bytes(4)};
  EXPECT_EQ(w->add_stored_chunk({}, bad).status().id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(compress_chunk(Bytes{1}, static_cast<Compression>(7)).status().id(),
            ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(compress_chunk(Bytes{1}, Compression::kZstd, {0, 6}).status().id(),
            ErrorId::kContainerWriterMisuse);
  ASSERT_TRUE(w->finish().ok());
  EXPECT_EQ(w->finish().id(), ErrorId::kContainerWriterMisuse);
  EXPECT_EQ(w->add_chunk({}, Bytes{1}, Compression::kNone).status().id(),
            ErrorId::kContainerWriterMisuse);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
}

std::string temp_path(const char* name) {
  return (std::filesystem::temp_directory_path() /
          (std::string("calf_container_test_") + std::to_string(::getpid()) + "_" + name))
      .string();
}

TEST(ContainerTest, FileIsWrittenWholeOrNotAtAll) {
  const std::string path = temp_path("whole.calf");
  std::filesystem::remove(path);
  {
    auto w = Writer::create(path);
    ASSERT_TRUE(w.ok()) << w.status().to_string();
    ASSERT_TRUE(w->add_track(MeshTrackHeader{}).ok());
    ASSERT_TRUE(w->add_chunk({}, Bytes(100, 7), Compression::kZstd).ok());
    // Dropped without finish(): nothing appears, no temporary is left behind.
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::temp_directory_path()))
    EXPECT_EQ(e.path().string().find(path + ".tmp"), std::string::npos) << e.path();
  {
    auto w = Writer::create(path);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->add_track(MeshTrackHeader{}).ok());
    ASSERT_TRUE(w->add_chunk({}, Bytes(100, 7), Compression::kZstd).ok());
    ASSERT_TRUE(w->finish().ok());
  }
  auto r = Reader::open(path);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(*r->read_chunk(0), Bytes(100, 7));
  EXPECT_TRUE(r->verify().empty());
  std::filesystem::remove(path);
  EXPECT_EQ(Reader::open(path).status().id(), ErrorId::kFileOpen);
  EXPECT_EQ(Writer::create("/nonexistent-dir/x.calf").status().id(), ErrorId::kFileWrite);
}

// A 1 GiB file whose chunk payloads are zeros, without storing them: the sink keeps every
// write except long runs of zeros; the source serves what was kept, zeros elsewhere, and counts
// every byte the reader asks for.
class SparseSink final : public ByteSink {
 public:
  explicit SparseSink(std::map<uint64_t, Bytes>* kept, uint64_t* size) : kept_(kept), size_(size) {}
  Status append(std::span<const uint8_t> b) override {
    const bool zeros = std::all_of(b.begin(), b.end(), [](uint8_t v) { return v == 0; });
    if (!(zeros && b.size() >= (1u << 20))) (*kept_)[*size_] = Bytes(b.begin(), b.end());
    *size_ += b.size();
    return Status::Ok();
  }
  Status patch(uint64_t offset, std::span<const uint8_t> b) override {
    Bytes& at = (*kept_)[offset];
    EXPECT_GE(at.size(), b.size());
    std::copy(b.begin(), b.end(), at.begin());
    return Status::Ok();
  }
  Status commit() override { return Status::Ok(); }

 private:
  std::map<uint64_t, Bytes>* kept_;
  uint64_t* size_;
};

class CountingSource final : public ByteSource {
 public:
  CountingSource(std::map<uint64_t, Bytes> kept, uint64_t size)
      : kept_(std::move(kept)), size_(size) {}
  uint64_t size() const override { return size_; }
  Status read_at(uint64_t offset, std::span<uint8_t> out) const override {
    bytes_read += out.size();
    reads.push_back({offset, out.size()});
    std::fill(out.begin(), out.end(), 0);
    for (const auto& [at, b] : kept_)
      for (size_t i = 0; i < b.size(); ++i)
        if (at + i >= offset && at + i < offset + out.size()) out[at + i - offset] = b[i];
    return Status::Ok();
  }
  mutable uint64_t bytes_read = 0;
  mutable std::vector<std::pair<uint64_t, uint64_t>> reads;

 private:
  std::map<uint64_t, Bytes> kept_;
  uint64_t size_;
};

TEST(ContainerTest, ReadingOneChunkOfAGibibyteFileTouchesOnlyIndexAndChunk) {
  std::map<uint64_t, Bytes> kept;
  uint64_t size = 0;
  {
    auto w = Writer::create(std::make_unique<SparseSink>(&kept, &size));
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->add_track(LightfieldTrackHeader{}).ok());
    StoredChunk c{Compression::kNone, 16u << 20, Bytes(16u << 20)};
    for (uint32_t i = 0; i < 64; ++i) {  // 64 x 16 MiB = 1 GiB of payload
      ChunkKeys k;
      k.view = i;
      ASSERT_TRUE(w->add_stored_chunk(k, c).ok());
    }
    ASSERT_TRUE(w->finish().ok());
  }
  auto source = std::make_unique<CountingSource>(std::move(kept), size);
  CountingSource* counter = source.get();
  ASSERT_GE(counter->size(), 1ull << 30);
  auto r = Reader::open(std::move(source));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  // open() read the header and the directory, nothing else.
  EXPECT_EQ(counter->bytes_read, kHeaderSize + r->header().directory_size);
  ChunkQuery q;
  q.view = 37;
  const auto ids = r->find_chunks(q);
  ASSERT_EQ(ids.size(), 1u);
  const ChunkEntry& e = r->chunks()[ids[0]];
  counter->reads.clear();
  counter->bytes_read = 0;
  auto chunk = r->read_chunk(ids[0]);
  ASSERT_TRUE(chunk.ok()) << chunk.status().to_string();
  EXPECT_EQ(counter->bytes_read, e.stored_size);  // that chunk's bytes, once
  for (const auto& [offset, n] : counter->reads) {
    EXPECT_GE(offset, e.offset);
    EXPECT_LE(offset + n, e.offset + e.stored_size);
  }
}

}  // namespace
}  // namespace calf::container
