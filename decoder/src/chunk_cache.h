// Decompressed chunks for the view-dependent decoder: read on demand or ahead of time by one
// background thread, kept up to a byte bound (least recently used out first). A chunk handed out
// stays alive while its holder keeps the shared_ptr, so eviction never pulls bytes from under a
// frame being decoded; the bound therefore holds for the cache itself, with the current frame's
// chunks on top.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf::decoder {

using ChunkBytes = std::shared_ptr<const std::vector<uint8_t>>;

class ChunkCache {
 public:
  // `reader` must outlive the cache. `background` starts the prefetch thread.
  ChunkCache(const container::Reader& reader, size_t limit_bytes, bool background);
  ~ChunkCache();
  ChunkCache(const ChunkCache&) = delete;
  ChunkCache& operator=(const ChunkCache&) = delete;

  // The raw bytes of chunk `id`: from the cache, from the background thread (waiting for it if
  // it is reading the chunk now), or read here; `*read_here` tells which. Failures are returned
  // and not cached, so a later call retries.
  Expected<ChunkBytes> get(uint32_t id, bool* read_here);
  // Queues chunks for the background thread (no-op without one, or for chunks already cached or
  // queued). The queue is cut to the newest `limit_bytes` worth of requests.
  void prefetch(std::span<const uint32_t> ids);
  // Empties the queue and waits for the thread to finish the chunk it is reading.
  void drain();

  size_t cached_bytes() const;

 private:
  enum class State : uint8_t { kQueued, kReading, kReady };
  struct Entry {
    State state = State::kQueued;
    ChunkBytes bytes;
    uint64_t last_use = 0;
  };
  void run();
  void store_locked(uint32_t id, ChunkBytes bytes);
  void evict_locked();

  const container::Reader* reader_;
  const size_t limit_;
  mutable std::mutex mutex_;
  std::condition_variable ready_, work_;
  std::unordered_map<uint32_t, Entry> entries_;
  std::deque<uint32_t> queue_;
  size_t bytes_ = 0;
  uint64_t clock_ = 0;
  bool stop_ = false;
  bool busy_ = false;
  std::thread worker_;
};

}  // namespace calf::decoder
