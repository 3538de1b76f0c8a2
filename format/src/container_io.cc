// File and memory byte sources and sinks (POSIX: pread, pwrite, mkstemp, fsync, rename).
#include "calf/format/container_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "calf/format/container_fields.h"

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
  FileSink(int fd, std::string temp, std::string path)
      : fd_(fd), temp_(std::move(temp)), path_(std::move(path)) {}
  ~FileSink() override {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(temp_.c_str());
  }
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
  Status commit() override {
    if (::fsync(fd_) != 0 || ::close(fd_) != 0) {
      fd_ = -1;
      return Status(ErrorId::kFileWrite, cat(temp_, ": ", errno_text()));
    }
    fd_ = -1;
    if (::rename(temp_.c_str(), path_.c_str()) != 0)
      return Status(ErrorId::kFileWrite, cat("rename ", temp_, " to ", path_, ": ", errno_text()));
    committed_ = true;
    return Status::Ok();
  }

 private:
  Status write_at(uint64_t offset, std::span<const uint8_t> bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done,
                                 static_cast<off_t>(offset + done));
      if (n < 0) {
        if (errno == EINTR) continue;
        return Status(ErrorId::kFileWrite, cat(temp_, ": write: ", errno_text()));
      }
      done += static_cast<size_t>(n);
    }
    return Status::Ok();
  }
  int fd_;
  std::string temp_, path_;
  uint64_t size_ = 0;
  bool committed_ = false;
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
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Status(ErrorId::kFileOpen, cat(path, ": ", errno_text()));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status(ErrorId::kFileOpen, cat(path, ": not a regular file"));
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
  // O_EXCL with mode 0666 lets the kernel apply the process umask, as for any new file (mkstemp
  // would create 0600, and reading the umask means changing it, which is process-global). The
  // name is unique per process and call; a stale file of the same name is skipped, not reused.
  static std::atomic<uint32_t> counter{0};
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string temp = cat(path, ".tmp-", static_cast<uint64_t>(::getpid()), "-",
                           static_cast<uint64_t>(counter.fetch_add(1)));
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return std::unique_ptr<ByteSink>(new FileSink(fd, std::move(temp), path));
    if (errno != EEXIST) break;
  }
  return Status(ErrorId::kFileWrite, cat(path, ": cannot create a temporary file: ", errno_text()));
}

std::unique_ptr<ByteSink> memory_sink(std::vector<uint8_t>* out) {
  return std::make_unique<MemorySink>(out);
}

}  // namespace calf::container
