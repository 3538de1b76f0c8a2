// Byte sources and sinks under the container Reader and Writer.
//
// The reader never reads a whole file: it asks its ByteSource for exact ranges (pread on a
// file), so reading one chunk touches only the header, the directory and that chunk. A source
// can be wrapped (e.g. to count the bytes read, or to serve a synthetic file in tests).
//
// The writer appends to a ByteSink and patches the header once at the end; the file sink
// writes a temporary file in the destination's directory and renames it into place on commit,
// so the destination holds either the whole new file or what it held before.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "calf/format/status.h"

namespace calf::container {

// Random-access bytes. read_at is const and must be safe to call from several threads at once
// (the file source uses pread, which has no shared file position).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // The size at open time.
  virtual uint64_t size() const = 0;
  // Fills `out` with the bytes at [offset, offset + out.size()). Ending early is
  // kContainerTruncated (the file shrank or the range is past its end); an OS failure kFileRead.
  virtual Status read_at(uint64_t offset, std::span<uint8_t> out) const = 0;
};

// Opens `path` for reading (kFileOpen on failure, also when it is not a regular file: checked
// before the open, so a FIFO never blocks; files.h). The size is taken once, by fstat.
Expected<std::unique_ptr<ByteSource>> open_file_source(const std::string& path);
// A source over memory the caller keeps alive (no copy).
std::unique_ptr<ByteSource> memory_source(std::span<const uint8_t> bytes);
// A source owning its bytes.
std::unique_ptr<ByteSource> memory_source(std::vector<uint8_t> bytes);

// Append-only output with one patch operation.
class ByteSink {
 public:
  virtual ~ByteSink() = default;
  // Appends bytes (kFileWrite on failure).
  virtual Status append(std::span<const uint8_t> bytes) = 0;
  // Overwrites bytes already appended (the writer patches the header at the end).
  virtual Status patch(uint64_t offset, std::span<const uint8_t> bytes) = 0;
  // Makes the output visible: the file sink flushes, fsyncs and renames. After a failed or
  // missing commit, destruction removes every trace of the output.
  virtual Status commit() = 0;
};

// A sink writing `path` through a temporary file beside it + rename (files::TempFile: an
// existing `path` that is not a regular file, or is a symbolic link, is refused with kFileWrite).
Expected<std::unique_ptr<ByteSink>> create_file_sink(const std::string& path);
// A sink writing into `*out` (which the caller keeps alive); commit() does nothing.
std::unique_ptr<ByteSink> memory_sink(std::vector<uint8_t>* out);

}  // namespace calf::container
