#include "chunk_cache.h"

#include <algorithm>

namespace calf::decoder {

ChunkCache::ChunkCache(const container::Reader& reader, size_t limit_bytes, bool background)
    : reader_(&reader), limit_(limit_bytes) {
  if (background) worker_ = std::thread([this] { run(); });
}

ChunkCache::~ChunkCache() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  if (worker_.joinable()) worker_.join();
}

size_t ChunkCache::cached_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

Expected<ChunkBytes> ChunkCache::get(uint32_t id, bool* read_here) {
  *read_here = false;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    auto it = entries_.find(id);
    if (it != entries_.end() && it->second.state == State::kReading) {
      ready_.wait(lock, [&] {
        it = entries_.find(id);
        return it == entries_.end() || it->second.state != State::kReading;
      });
    }
    if (it != entries_.end() && it->second.state == State::kReady) {
      it->second.last_use = ++clock_;
      return it->second.bytes;
    }
    // Queued but not started (or failed on the thread): take it over.
    if (it != entries_.end()) {
      entries_.erase(it);
      queue_.erase(std::remove(queue_.begin(), queue_.end(), id), queue_.end());
    }
  }
  *read_here = true;
  Expected<std::vector<uint8_t>> raw = reader_->read_chunk(id);
  if (!raw.ok()) return raw.status();
  auto bytes = std::make_shared<const std::vector<uint8_t>>(std::move(*raw));
  std::lock_guard<std::mutex> lock(mutex_);
  store_locked(id, bytes);
  return ChunkBytes(bytes);
}

void ChunkCache::prefetch(std::span<const uint32_t> ids) {
  if (!worker_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (uint32_t id : ids) {
      if (entries_.count(id) != 0 || id >= reader_->chunks().size()) continue;
      entries_[id] = Entry{};
      queue_.push_back(id);
    }
    // Requests beyond the byte bound would only evict each other: keep the newest.
    size_t queued = 0;
    for (auto it = queue_.rbegin(); it != queue_.rend(); ++it) {
      queued += reader_->chunks()[*it].raw_size;
      if (queued > limit_) {
        for (auto drop = queue_.begin(); drop != it.base(); ++drop) entries_.erase(*drop);
        queue_.erase(queue_.begin(), it.base());
        break;
      }
    }
  }
  work_.notify_one();
}

void ChunkCache::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (uint32_t id : queue_) entries_.erase(id);
  queue_.clear();
  ready_.wait(lock, [&] { return !busy_; });
}

void ChunkCache::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    work_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    const uint32_t id = queue_.front();
    queue_.pop_front();
    entries_[id].state = State::kReading;
    busy_ = true;
    lock.unlock();
    Expected<std::vector<uint8_t>> raw = reader_->read_chunk(id);
    lock.lock();
    busy_ = false;
    if (raw.ok()) {
      store_locked(id, std::make_shared<const std::vector<uint8_t>>(std::move(*raw)));
    } else {
      entries_.erase(id);  // the decoder reads it itself and reports the error
    }
    ready_.notify_all();
  }
}

void ChunkCache::store_locked(uint32_t id, ChunkBytes bytes) {
  Entry& e = entries_[id];
  if (e.state == State::kReady) bytes_ -= e.bytes->size();
  e.state = State::kReady;
  e.bytes = std::move(bytes);
  e.last_use = ++clock_;
  bytes_ += e.bytes->size();
  evict_locked();
}

void ChunkCache::evict_locked() {
  while (bytes_ > limit_) {
    auto victim = entries_.end();
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      if (it->second.state != State::kReady) continue;
      if (victim == entries_.end() || it->second.last_use < victim->second.last_use) victim = it;
    }
    if (victim == entries_.end()) return;
    bytes_ -= victim->second.bytes->size();
    entries_.erase(victim);
  }
}

}  // namespace calf::decoder
