// The path rules of calf/format/files.h: inputs that are not regular files are refused without
// blocking, outputs are replaced only when they are regular files, an output is never an input,
// temporary files disappear on an error, on a signal, and (stale ones) on the next run.
#include "calf/format/files.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <vector>

#include "calf/format/container.h"

namespace calf::files {
namespace {

namespace fs = std::filesystem;

class FilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("calf_files_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // Names in the directory holding ".tmp-".
  std::vector<std::string> temp_names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n.find(".tmp-") != std::string::npos) out.push_back(n);
    }
    return out;
  }
  fs::path dir_;
};

void write_text(const std::string& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

std::string read_text(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST_F(FilesTest, OutputMayBeAbsentOrARegularFileOnly) {
  EXPECT_TRUE(check_output_file(path("new.calf")).ok());
  write_text(path("old.calf"), "x");
  EXPECT_TRUE(check_output_file(path("old.calf")).ok());

  fs::create_directories(path("dir.calf"));
  Status s = check_output_file(path("dir.calf"));
  EXPECT_EQ(s.id(), ErrorId::kFileWrite);
  EXPECT_NE(s.message().find("a directory"), std::string::npos) << s.message();

  ASSERT_EQ(::mkfifo(path("fifo.calf").c_str(), 0600), 0);
  s = check_output_file(path("fifo.calf"));
  EXPECT_EQ(s.id(), ErrorId::kFileWrite);
  EXPECT_NE(s.message().find("a FIFO"), std::string::npos) << s.message();

  fs::create_symlink("old.calf", path("link.calf"));
  s = check_output_file(path("link.calf"));
  EXPECT_EQ(s.id(), ErrorId::kFileWrite);
  EXPECT_NE(s.message().find("symbolic link"), std::string::npos) << s.message();
}

// The container writer (and through TempFile every writer) leaves a FIFO, a directory and a
// symbolic link where they are, untouched.
TEST_F(FilesTest, ContainerWriterRefusesNonRegularDestinations) {
  ASSERT_EQ(::mkfifo(path("fifo.calf").c_str(), 0600), 0);
  fs::create_directories(path("dir.calf"));
  write_text(path("target"), "keep");
  fs::create_symlink("target", path("link.calf"));
  for (const char* name : {"fifo.calf", "dir.calf", "link.calf"}) {
    auto w = container::Writer::create(path(name));
    ASSERT_FALSE(w.ok()) << name;
    EXPECT_EQ(w.status().id(), ErrorId::kFileWrite) << name;
  }
  EXPECT_TRUE(fs::is_fifo(path("fifo.calf")));
  EXPECT_TRUE(fs::is_directory(path("dir.calf")));
  EXPECT_TRUE(fs::is_symlink(path("link.calf")));
  EXPECT_EQ(read_text(path("target")), "keep");
  EXPECT_TRUE(temp_names().empty());
}

// Reading a FIFO returns an error at once instead of waiting for a writer forever.
TEST_F(FilesTest, ReaderRefusesAFifoWithoutBlocking) {
  const std::string fifo = path("f.calf");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto opened = std::async(std::launch::async, [&] { return container::Reader::open(fifo); });
  if (opened.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    // Unblock the stuck open so that the test can end, then fail.
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
    opened.wait();
    FAIL() << "Reader::open blocked on a FIFO";
  }
  auto r = opened.get();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kFileOpen);
  EXPECT_NE(r.status().message().find("not a regular file (a FIFO)"), std::string::npos)
      << r.status().message();
  // The path is named once.
  const std::string m = r.status().message();
  EXPECT_EQ(m.find(fifo), m.rfind(fifo)) << m;

  auto fd = open_regular_file(path("missing"));
  EXPECT_EQ(fd.status().id(), ErrorId::kFileOpen);
  EXPECT_EQ(open_regular_file(dir_.string()).status().id(), ErrorId::kFileOpen);
}

// A later error of Reader::open (not the open itself) names the path once too.
TEST_F(FilesTest, ReaderErrorsNameThePathOnce) {
  write_text(path("short.calf"), "not a calf file at all");
  auto r = container::Reader::open(path("short.calf"));
  ASSERT_FALSE(r.ok());
  const std::string m = r.status().message();
  EXPECT_EQ(m.find(path("short.calf")), 0u) << m;
  EXPECT_EQ(m.find(path("short.calf")), m.rfind(path("short.calf"))) << m;
}

TEST_F(FilesTest, OutputIsInputByInodeAndLinks) {
  write_text(path("manifest.json"), "{}");
  write_text(path("other"), "{}");
  fs::create_hard_link(path("manifest.json"), path("hard"));
  fs::create_symlink("manifest.json", path("soft"));
  const std::vector<std::string> inputs = {dir_.string(), path("manifest.json")};
  for (const std::string& out : {path("manifest.json"), path("hard"), path("soft"),
                                 (dir_ / "." / "manifest.json").string(), dir_.string()}) {
    const Status s = check_output_not_input(out, inputs);
    EXPECT_EQ(s.id(), ErrorId::kOutputIsInput) << out;
    EXPECT_NE(s.message().find(out), std::string::npos) << s.message();
  }
  EXPECT_TRUE(check_output_not_input(path("other"), inputs).ok());
  EXPECT_TRUE(check_output_not_input(path("absent.calf"), inputs).ok());
}

TEST_F(FilesTest, TempFileIsRemovedUnlessCommitted) {
  std::string temp;
  {
    auto t = TempFile::create(path("out.bin"));
    ASSERT_TRUE(t.ok()) << t.status().to_string();
    temp = t->temp_path();
    EXPECT_EQ(temp.rfind(path("out.bin") + ".tmp-", 0), 0u) << temp;
    EXPECT_TRUE(fs::exists(temp));
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(path("out.bin")));

  write_text(path("out.bin"), "old");
  auto t = TempFile::create(path("out.bin"));
  ASSERT_TRUE(t.ok());
  const std::string bytes = "new";
  ASSERT_TRUE(t->write(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), 3)).ok());
  ASSERT_TRUE(t->commit().ok());
  EXPECT_EQ(read_text(path("out.bin")), "new");
  EXPECT_TRUE(temp_names().empty());
}

// A FIFO put in the destination's place while the file was written is not replaced.
TEST_F(FilesTest, CommitRechecksTheDestination) {
  auto t = TempFile::create(path("out.bin"));
  ASSERT_TRUE(t.ok());
  ASSERT_EQ(::mkfifo(path("out.bin").c_str(), 0600), 0);
  EXPECT_EQ(t->commit().id(), ErrorId::kFileWrite);
  EXPECT_TRUE(fs::is_fifo(path("out.bin")));
  EXPECT_TRUE(temp_names().empty());
}

// The name of a temporary file of `dest` as process `pid` of this host would have made it.
std::string temp_name_for_pid(const std::string& dest, long pid) {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return dest + ".tmp-" + host + "-" + std::to_string(pid) + "-7";
}

TEST_F(FilesTest, TempFileNamesFollowTheDocumentedPattern) {
  auto t = TempFile::create(path("clip.calf"));
  ASSERT_TRUE(t.ok());
  std::string expected = temp_name_for_pid(path("clip.calf"), ::getpid());
  expected = expected.substr(0, expected.rfind('-') + 1);
  EXPECT_EQ(t->temp_path().rfind(expected, 0), 0u) << t->temp_path() << " vs " << expected;
}

TEST_F(FilesTest, StaleTempFilesOfDeadProcessesAreRemoved) {
  // A process that has ended: a child that exits at once, reaped.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);

  const std::string dead = temp_name_for_pid(path("clip.calf"), child);
  const std::string alive = temp_name_for_pid(path("clip.calf"), ::getppid());
  const std::string self = temp_name_for_pid(path("other.exr"), ::getpid());
  std::string other_host = dead;
  other_host.replace(other_host.find(".tmp-") + 5, 0, "elsewhere.invalid-");
  for (const std::string& p : {dead, alive, self, other_host}) write_text(p, "partial");
  // A directory with a stale name is not calf's temporary file.
  const std::string dead_dir = temp_name_for_pid(path("dir.calf"), child);
  fs::create_directories(dead_dir);
  write_text(path("clip.calf.tmp"), "not of calf's naming");

  EXPECT_EQ(remove_stale_temp_files(dir_.string()), 1u);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(self));
  EXPECT_TRUE(fs::exists(other_host));
  EXPECT_TRUE(fs::is_directory(dead_dir));
  EXPECT_TRUE(fs::exists(path("clip.calf.tmp")));
}

// The first TempFile of a process in a directory sweeps it; a child process is a fresh process.
TEST_F(FilesTest, TheNextWriterSweepsTheDirectory) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  const std::string dead = temp_name_for_pid(path("clip.calf"), child);
  write_text(dead, "partial");
  // This process already swept dir_ (in temp_name_for_pid): run the writer in a new process.
  const pid_t writer = ::fork();
  if (writer == 0) {
    auto w = container::Writer::create(path("clip.calf"));
    ::_exit(w.ok() && w->finish().ok() ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(writer, &status, 0), writer);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::is_regular_file(path("clip.calf")));
  EXPECT_TRUE(temp_names().empty());
}

// SIGTERM (and SIGINT, SIGHUP) remove the temporary files being written, then end the process
// by that signal.
TEST_F(FilesTest, SignalsRemoveTemporaryFiles) {
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    if (child == 0) {
      install_temp_file_cleanup();
      auto a = TempFile::create(path("a.calf"));
      auto b = TempFile::create(path("b.exr"));
      if (!a.ok() || !b.ok()) ::_exit(3);
      const char c = 'x';
      if (::write(ready[1], &c, 1) != 1) ::_exit(4);
      for (;;) ::pause();
    }
    ASSERT_GT(child, 0);
    ::close(ready[1]);
    char c = 0;
    ASSERT_EQ(::read(ready[0], &c, 1), 1);
    ::close(ready[0]);
    EXPECT_EQ(temp_names().size(), 2u);
    ASSERT_EQ(::kill(child, sig), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "signal " << sig;
    EXPECT_TRUE(temp_names().empty()) << "signal " << sig;
  }
}

}  // namespace
}  // namespace calf::files
