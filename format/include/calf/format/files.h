// The one place where calf decides what a path it reads or writes may be (POSIX).
//
// Inputs: a path calf reads must be a regular file (symbolic links followed). A directory, a
// FIFO, a device node or a socket is refused with CALF-E002 *before* it is opened, and the open
// itself is non-blocking, so a FIFO can never stall a command (open_regular_file).
//
// Outputs: calf writes every output whole, through a temporary file beside it that is renamed
// over the destination (format/SPEC.md §12). The destination may be absent or an existing regular
// file; anything else is refused with CALF-E004 and left untouched: a directory, a FIFO, a device
// node (renaming over /dev/null would replace it), a socket, and a symbolic link (a rename would
// replace the link itself, not write through it; name the link's target instead).
//
// Temporary files are named `<destination>.tmp-<host>-<pid>-<n>`. A process registers each one
// while it exists, so the handler of install_temp_file_cleanup() can remove them when SIGINT,
// SIGTERM or SIGHUP ends the process; and the first TempFile a process creates in a directory
// removes the temporary files of that naming left there by processes of the same host that are
// no longer alive (a kill -9, a power cut).
#pragma once

#include <span>
#include <string>

#include "calf/format/status.h"

namespace calf::files {

// "a directory", "a FIFO", "a character device", "a block device", "a socket", "a symbolic link"
// or "not a regular file" for a struct stat st_mode.
const char* file_type_name(unsigned mode);

// Ok when `path` is a regular file (after following links). Else CALF-E002 naming the path and
// what it is ("no such file" and the like when stat fails). Never opens the path.
Status check_regular_file(const std::string& path);

// Opens an existing regular file read-only (O_CLOEXEC) and returns its descriptor, which the
// caller closes. check_regular_file first, then a non-blocking open re-checked with fstat, so a
// FIFO swapped in between cannot block either. Errors: CALF-E002.
Expected<int> open_regular_file(const std::string& path);

// Ok when `path` may be written as an output: it does not exist, or it is a regular file (not a
// symbolic link to one). Else CALF-E004 naming the path and what it is. Never creates anything.
Status check_output_file(const std::string& path);

// Ok when `output` is none of `inputs`: an existing output is compared with each existing input
// by device and inode (so hard and symbolic links, bind mounts and other spellings of a path
// count as the same file); an output that does not exist replaces nothing. Else CALF-E007
// naming both (the input also by its canonical path).
Status check_output_not_input(const std::string& output, std::span<const std::string> inputs);

// A temporary file beside a destination, removed unless commit() renamed it into place.
class TempFile {
 public:
  // check_output_file(path), the stale-file sweep of path's directory (once per directory and
  // process), then a new empty file `<path>.tmp-<host>-<pid>-<n>` created with O_EXCL (mode 0666
  // less the umask) and registered for removal on a signal. Errors: CALF-E004.
  static Expected<TempFile> create(const std::string& path);

  TempFile(TempFile&& other) noexcept;
  TempFile& operator=(TempFile&& other) noexcept;
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  // Removes the temporary file unless it was committed.
  ~TempFile();

  const std::string& path() const { return path_; }            // the destination
  const std::string& temp_path() const { return temp_path_; }  // the file being written
  // The open descriptor (O_WRONLY), or -1 after close_fd().
  int fd() const { return fd_; }
  // Closes the descriptor, for writers that reopen temp_path() by name (image libraries).
  void close_fd();
  // Appends bytes at the descriptor's position. Errors: CALF-E004.
  Status write(std::span<const uint8_t> bytes);
  // fsync (when `sync`) and close, check_output_file(path) again, rename the temporary file over
  // the destination. On failure the temporary file is removed. Errors: CALF-E004.
  Status commit(bool sync = true);

 private:
  TempFile() = default;
  void release();
  std::string path_, temp_path_;
  int fd_ = -1;
  int slot_ = -1;  // the signal registry slot, or -1
  bool committed_ = false;
};

// Removes, from `directory`, the regular files named `*.tmp-<host>-<pid>-<n>` whose host is this
// one and whose process no longer exists; returns how many were removed. TempFile::create calls
// it; exposed for tests.
size_t remove_stale_temp_files(const std::string& directory);

// Installs handlers for SIGINT, SIGTERM and SIGHUP (each unless the process ignores it) that
// remove every registered temporary file, then end the process by the same signal. For commands
// only: a library never changes a process's signal dispositions. Idempotent.
void install_temp_file_cleanup();

}  // namespace calf::files
