// Input and output path rules, temporary files and their cleanup (calf/format/files.h).
#include "calf/format/files.h"

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>

#include "calf/format/container_fields.h"

namespace calf::files {
namespace {

using container::cat;

std::string errno_text(int e) {
  return std::strerror(e);
}

std::string directory_of(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// This host's name as it appears in temporary file names: no '/' and not empty.
const std::string& host_name() {
  static const std::string name = [] {
    char buffer[256] = {};
    if (::gethostname(buffer, sizeof buffer - 1) != 0 || buffer[0] == 0)
      std::strcpy(buffer, "host");
    std::string s(buffer);
    for (char& c : s)
      if (c == '/' || static_cast<unsigned char>(c) < 0x20) c = '_';
    return s;
  }();
  return name;
}

// ---- the registry the signal handler reads ----------------------------------------------------
// Fixed slots, so that the handler touches no allocator and no lock: a slot is free (0), being
// filled (1) or holds a path to remove (2).
constexpr int kSlots = 256;
struct Slot {
  std::atomic<int> state{0};
  char path[PATH_MAX];
};
Slot g_slots[kSlots];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

int register_temp(const std::string& path) {
  if (path.size() >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1, std::memory_order_acquire)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].state.store(2, std::memory_order_release);
      return i;
    }
  }
  return -1;  // more temporary files at once than slots: these are not removed on a signal
}

void unregister_temp(int slot) {
  if (slot >= 0) g_slots[slot].state.store(0, std::memory_order_release);
}

extern "C" void remove_temps_and_reraise(int sig) {
  const int saved = errno;
  for (Slot& s : g_slots) {
    if (s.state.load(std::memory_order_acquire) == 2) ::unlink(s.path);
  }
  errno = saved;
  // SA_RESETHAND restored the default action: the process ends by the same signal.
  ::raise(sig);
}

// Parses `<anything>.tmp-<host>-<pid>-<n>`; false when `name` is not of that form.
bool parse_temp_name(const std::string& name, std::string* host, long* pid) {
  const size_t last = name.rfind('-');
  if (last == std::string::npos || last + 1 == name.size()) return false;
  for (size_t i = last + 1; i < name.size(); ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  const size_t before = name.rfind('-', last - 1);
  if (before == std::string::npos || before + 1 == last || last - before > 10) return false;
  long p = 0;
  for (size_t i = before + 1; i < last; ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
    p = p * 10 + (name[i] - '0');
  }
  const size_t tag = name.rfind(".tmp-", before);
  if (tag == std::string::npos || tag == 0 || tag + 5 >= before) return false;
  *host = name.substr(tag + 5, before - tag - 5);
  *pid = p;
  return true;
}

bool process_alive(long pid) {
  if (pid <= 0) return true;  // not a process id calf writes: keep the file
  if (pid == static_cast<long>(::getpid())) return true;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

const char* file_type_name(unsigned mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

Status check_regular_file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    return Status(ErrorId::kFileOpen, cat(path, ": ", errno_text(errno)));
  }
  if (!S_ISREG(st.st_mode)) {
    return Status(ErrorId::kFileOpen,
                  cat(path, ": not a regular file (", file_type_name(st.st_mode), ")"));
  }
  return Status::Ok();
}

Expected<int> open_regular_file(const std::string& path) {
  CALF_RETURN_IF_ERROR(check_regular_file(path));
  // O_NONBLOCK: should a FIFO take the file's place after the check, open does not wait for a
  // writer; fstat then refuses it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return Status(ErrorId::kFileOpen, cat(path, ": ", errno_text(errno)));
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status(ErrorId::kFileOpen, cat(path, ": not a regular file"));
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  return fd;
}

Status check_output_file(const std::string& path) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return Status::Ok();
    return Status(ErrorId::kFileWrite, cat(path, ": ", errno_text(errno)));
  }
  if (S_ISREG(st.st_mode)) return Status::Ok();
  if (S_ISLNK(st.st_mode)) {
    return Status(ErrorId::kFileWrite,
                  cat(path,
                      ": is a symbolic link; calf replaces outputs by rename and does not replace "
                      "links (name the link's target)"));
  }
  return Status(ErrorId::kFileWrite, cat(path, ": exists and is ", file_type_name(st.st_mode),
                                         "; calf writes outputs only as regular files"));
}

Status check_output_not_input(const std::string& output, std::span<const std::string> inputs) {
  // An output that does not exist replaces nothing. One that does is compared by device and
  // inode, which sees through hard links, symbolic links, bind mounts and spellings ("./a//b").
  struct stat out_st;
  if (::stat(output.c_str(), &out_st) != 0) return Status::Ok();
  for (const std::string& input : inputs) {
    struct stat in_st;
    if (::stat(input.c_str(), &in_st) != 0) continue;
    if (in_st.st_dev == out_st.st_dev && in_st.st_ino == out_st.st_ino) {
      std::error_code ec;
      const std::filesystem::path canonical = std::filesystem::canonical(input, ec);
      return Status(ErrorId::kOutputIsInput,
                    cat("output ", output, " is the input ", input,
                        ec ? std::string() : cat(" (", canonical.string(), ")"),
                        "; an output must not replace an input"));
    }
  }
  return Status::Ok();
}

// ---- TempFile -----------------------------------------------------------------------------------

Expected<TempFile> TempFile::create(const std::string& path) {
  CALF_RETURN_IF_ERROR(check_output_file(path));
  {
    static std::mutex mutex;
    static std::set<std::string> swept;
    const std::string dir = directory_of(path);
    std::lock_guard<std::mutex> lock(mutex);
    if (swept.insert(dir).second) remove_stale_temp_files(dir);
  }
  static std::atomic<uint64_t> counter{0};
  TempFile t;
  t.path_ = path;
  int error = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    t.temp_path_ = cat(path, ".tmp-", host_name(), "-", static_cast<uint64_t>(::getpid()), "-",
                       counter.fetch_add(1));
    // Registered before it exists, so that no moment is left where a signal would leave it.
    t.slot_ = register_temp(t.temp_path_);
    // O_EXCL with mode 0666 lets the kernel apply the umask, as for any new file.
    t.fd_ = ::open(t.temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (t.fd_ >= 0) return t;
    error = errno;
    unregister_temp(t.slot_);
    t.slot_ = -1;
    if (error != EEXIST) break;
  }
  t.temp_path_.clear();  // nothing of ours to remove
  return Status(ErrorId::kFileWrite,
                cat(path, ": cannot create a temporary file: ", errno_text(error)));
}

TempFile::TempFile(TempFile&& other) noexcept {
  *this = std::move(other);
}

TempFile& TempFile::operator=(TempFile&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    temp_path_ = std::move(other.temp_path_);
    fd_ = other.fd_;
    slot_ = other.slot_;
    committed_ = other.committed_;
    other.temp_path_.clear();
    other.fd_ = -1;
    other.slot_ = -1;
  }
  return *this;
}

TempFile::~TempFile() {
  release();
}

void TempFile::release() {
  close_fd();
  if (!committed_ && !temp_path_.empty()) ::unlink(temp_path_.c_str());
  unregister_temp(slot_);
  slot_ = -1;
  temp_path_.clear();
}

void TempFile::close_fd() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

Status TempFile::write(std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Status(ErrorId::kFileWrite, cat(temp_path_, ": write: ", errno_text(errno)));
    }
    done += static_cast<size_t>(n);
  }
  return Status::Ok();
}

Status TempFile::commit(bool sync) {
  if (fd_ >= 0) {
    const bool synced = !sync || ::fsync(fd_) == 0;
    const int e = errno;
    const bool closed = ::close(fd_) == 0;
    fd_ = -1;
    if (!synced || !closed) {
      const Status s(ErrorId::kFileWrite, cat(temp_path_, ": ", errno_text(synced ? errno : e)));
      release();
      return s;
    }
  }
  // Again just before the rename: a FIFO or a link put there while the file was written.
  if (Status s = check_output_file(path_); !s.ok()) {
    release();
    return s;
  }
  if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const Status s(ErrorId::kFileWrite,
                   cat("rename ", temp_path_, " to ", path_, ": ", errno_text(errno)));
    release();
    return s;
  }
  committed_ = true;
  release();
  return Status::Ok();
}

size_t remove_stale_temp_files(const std::string& directory) {
  DIR* dir = ::opendir(directory.c_str());
  if (!dir) return 0;
  size_t removed = 0;
  while (const dirent* e = ::readdir(dir)) {
    const std::string name = e->d_name;
    std::string host;
    long pid = 0;
    if (!parse_temp_name(name, &host, &pid) || host != host_name() || process_alive(pid)) continue;
    const std::string full = directory + "/" + name;
    struct stat st;
    if (::lstat(full.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    if (::unlink(full.c_str()) == 0) ++removed;
  }
  ::closedir(dir);
  return removed;
}

void install_temp_file_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;
      struct sigaction sa {};
      sa.sa_handler = remove_temps_and_reraise;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_RESETHAND;
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

}  // namespace calf::files
