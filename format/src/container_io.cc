// File and memory byte sources and sinks (POSIX: pread, pwrite; files.h: temporary file, rename).
#include "calf/format/container_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "calf/format/container_fields.h"
#include "calf/format/files.h"

namespace calf::container {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

Status range_error(uint64_t offset, uint64_t n, uint64_t size) {
  return Status(ErrorId::kContainerTruncated, cat("cannot read ", n, " bytes at offset ", offset,
                                                  ": the input has ", size, " bytes"));
}

class FileSource final : public ByteSource {
 public:
  FileSource(int fd, uint64_t size, std::string path)
      : fd_(fd), size_(size), path_(std::move(path)) {}
  ~FileSource() override { ::close(fd_); }
  uint64_t size() const override { return size_; }
  Status read_at(uint64_t offset, std::span<uint8_t> out) const override {
    size_t done = 0;
    while (done < out.size()) {
      const ssize_t n =
          ::pread(fd_, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
      if (n < 0) {
        if (errno == EINTR) continue;
        return Status(ErrorId::kFileRead,
                      cat(path_, ": read at offset ", offset + done, ": ", errno_text()));
      }
      // End of file before the range ends: the file shrank after it was opened.
      if (n == 0) return range_error(offset, out.size(), offset + done);
      done += static_cast<size_t>(n);
    }
    return Status::Ok();
  }

 private:
  int fd_;
  uint64_t size_;
  std::string path_;
};

class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::span<const uint8_t> view) : view_(view) {}
  explicit MemorySource(std::vector<uint8_t> owned) : owned_(std::move(owned)), view_(owned_) {}
  uint64_t size() const override { return view_.size(); }
  Status read_at(uint64_t offset, std::span<uint8_t> out) const override {
    if (offset > view_.size() || out.size() > view_.size() - offset)
      return range_error(offset, out.size(), view_.size());
    if (!out.empty()) std::memcpy(out.data(), view_.data() + offset, out.size());
    return Status::Ok();
  }

 private:
  std::vector<uint8_t> owned_;
  std::span<const uint8_t> view_;
};

class FileSink final : public ByteSink {
 public:
  explicit FileSink(files::TempFile temp) : temp_(std::move(temp)) {}
  Status append(std::span<const uint8_t> bytes) override {
    CALF_RETURN_IF_ERROR(write_at(size_, bytes));
    size_ += bytes.size();
    return Status::Ok();
  }
  Status patch(uint64_t offset, std::span<const uint8_t> bytes) override {
    if (offset + bytes.size() > size_)
      return Status(ErrorId::kInternal, cat("patch at ", offset, " past the end ", size_));
    return write_at(offset, bytes);
  }
  Status commit() override { return temp_.commit(); }

 private:
  Status write_at(uint64_t offset, std::span<const uint8_t> bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::pwrite(temp_.fd(), bytes.data() + done, bytes.size() - done,
                                 static_cast<off_t>(offset + done));
      if (n < 0) {
        if (errno == EINTR) continue;
        return Status(ErrorId::kFileWrite, cat(temp_.temp_path(), ": write: ", errno_text()));
      }
      done += static_cast<size_t>(n);
    }
    return Status::Ok();
  }
  files::TempFile temp_;  // removed on destruction unless committed
  uint64_t size_ = 0;
};

class MemorySink final : public ByteSink {
 public:
  explicit MemorySink(std::vector<uint8_t>* out) : out_(out) { out_->clear(); }
  Status append(std::span<const uint8_t> bytes) override {
    out_->insert(out_->end(), bytes.begin(), bytes.end());
    return Status::Ok();
  }
  Status patch(uint64_t offset, std::span<const uint8_t> bytes) override {
    if (offset + bytes.size() > out_->size())
      return Status(ErrorId::kInternal, cat("patch at ", offset, " past the end ", out_->size()));
    if (!bytes.empty()) std::memcpy(out_->data() + offset, bytes.data(), bytes.size());
    return Status::Ok();
  }
  Status commit() override { return Status::Ok(); }

 private:
  std::vector<uint8_t>* out_;
};

}  // namespace

Expected<std::unique_ptr<ByteSource>> open_file_source(const std::string& path) {
  // A regular file only, checked before the (non-blocking) open: a FIFO never blocks a reader.
  CALF_ASSIGN_OR_RETURN(const int fd, files::open_regular_file(path));
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    return Status(ErrorId::kFileOpen, cat(path, ": ", errno_text()));
  }
  return std::unique_ptr<ByteSource>(new FileSource(fd, static_cast<uint64_t>(st.st_size), path));
}

std::unique_ptr<ByteSource> memory_source(std::span<const uint8_t> bytes) {
  return std::make_unique<MemorySource>(bytes);
}
std::unique_ptr<ByteSource> memory_source(std::vector<uint8_t> bytes) {
  return std::make_unique<MemorySource>(std::move(bytes));
}

Expected<std::unique_ptr<ByteSink>> create_file_sink(const std::string& path) {
  // The output rules (regular file or absent, temporary file naming, cleanup) are files.h's.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(path));
  return std::unique_ptr<ByteSink>(new FileSink(std::move(temp)));
}

std::unique_ptr<ByteSink> memory_sink(std::vector<uint8_t>* out) {
  return std::make_unique<MemorySink>(out);
}

}  // namespace calf::container
