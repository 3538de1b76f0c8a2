// The track registry (track_kinds.h, track_registry.h) walked kind by kind: every registered
// kind has a name, a SPEC section, named streams, a header that round-trips through the fields
// visitor, a reader that decodes it and a calf-info that prints it; a kind the list lacks is
// skipped when optional and refused (CALF-E050) when must-understand.
#include "calf/format/track_registry.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "calf/format/container.h"
#include "run_command.h"

namespace calf::container {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

// Sets every integer field to a distinct valid value (inside its Range, away from the defaults),
// so a round trip that lost or swapped a field would show. Written for the test, not taken from
// the code under test.
class Filler {
 public:
  template <UnsignedField T>
  void operator()(T& v, const char* name, Range r = {}) {
    const uint64_t max = std::min<uint64_t>(r.max, std::numeric_limits<T>::max());
    const uint64_t span = std::min<uint64_t>(max - r.min, 999);
    v = static_cast<T>(r.min + (next_++ * 7 + 3) % (span + 1));
    expected_.push_back({name, std::to_string(static_cast<uint64_t>(v))});
  }
  template <class T, class... A>
  void operator()(T&, const char* name, A...) {
    ADD_FAILURE() << name << ": a track header field the test cannot fill";
  }
  std::vector<std::pair<std::string, std::string>> expected_;

 private:
  uint64_t next_ = 1;
};

template <size_t... I>
TrackHeader header_at(size_t index, std::index_sequence<I...>) {
  TrackHeader h;
  ((index == I ? (void)h.emplace<I>() : (void)0), ...);
  return h;
}

// A header of list entry `i` with every field filled; `expected` gets (name, value) pairs.
TrackHeader filled_header(size_t i, std::vector<std::pair<std::string, std::string>>* expected) {
  TrackHeader h = header_at(i + 1, std::make_index_sequence<std::variant_size_v<TrackHeader>>{});
  Filler f;
  std::visit(
      [&](auto& x) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, std::monostate>)
          std::decay_t<decltype(x)>::fields(x, f);
      },
      h);
  *expected = f.expected_;
  return h;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TrackRegistry, EveryKindHasANameASectionAndStreams) {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  ASSERT_NE(root, nullptr) << "ctest sets CALF_SOURCE_DIR";
  const std::string spec = read_text(fs::path(root) / "format" / "SPEC.md");
  std::set<std::string> names;
  std::set<uint16_t> numbers;
  ASSERT_EQ(std::size(kTrackKinds) + 1, std::variant_size_v<TrackHeader>);
  for (size_t i = 0; i < std::size(kTrackKinds); ++i) {
    const auto kind = static_cast<uint16_t>(kTrackKinds[i]);
    const std::string name = track_kind_name(kind);
    SCOPED_TRACE(name);
    EXPECT_NE(kind, 0);
    EXPECT_TRUE(is_known_track_kind(kind));
    EXPECT_NE(name, "unknown");
    EXPECT_TRUE(names.insert(name).second) << "two kinds named " << name;
    EXPECT_TRUE(numbers.insert(kind).second) << "two kinds numbered " << kind;
    // Streams: tag 0 is the index chunk; every tag below the count is named.
    ASSERT_GE(stream_count(kind), 2);
    EXPECT_STREQ(stream_name(kind, 0), "index");
    for (uint16_t s = 0; s < stream_count(kind); ++s) EXPECT_STRNE(stream_name(kind, s), "");
    EXPECT_STREQ(stream_name(kind, stream_count(kind)), "");
    // SPEC.md §11 has the kind's section, headed "### <section> <Name> (kind <n>)", and §6.1
    // names it with its number.
    const std::string section = track_kind_section(kind);
    if (section == "none") {
      // The test build's own kind (tests/test_kind/) has no section: §11 reserves its number.
      EXPECT_NE(spec.find("Kind " + std::to_string(kind) +
                          " is reserved for calf's test-only kind (`" + name + "`"),
                std::string::npos);
      continue;
    }
    const size_t at = spec.find("\n### " + section + " ");
    ASSERT_NE(at, std::string::npos) << "SPEC.md lacks section " << section;
    const std::string heading = spec.substr(at + 1, spec.find('\n', at + 1) - at - 1);
    EXPECT_NE(heading.find("(kind " + std::to_string(kind) + ")"), std::string::npos) << heading;
    std::string title = name;
    title[0] = static_cast<char>(std::toupper(title[0]));
    EXPECT_NE(heading.find(title), std::string::npos) << heading;
    EXPECT_NE(spec.find(std::to_string(kind) + " " + name), std::string::npos);
  }
  EXPECT_STREQ(track_kind_name(0), "unknown");
  EXPECT_STREQ(track_kind_name(0x7777), "unknown");
  EXPECT_FALSE(is_known_track_kind(0x7777));
  EXPECT_EQ(stream_count(0x7777), 0);
}

TEST(TrackRegistry, EveryHeaderRoundTripsThroughTheVisitor) {
  for (size_t i = 0; i < std::size(kTrackKinds); ++i) {
    const auto kind = static_cast<uint16_t>(kTrackKinds[i]);
    SCOPED_TRACE(track_kind_name(kind));
    std::vector<std::pair<std::string, std::string>> expected;
    const TrackHeader h = filled_header(i, &expected);
    EXPECT_EQ(track_header_kind(h), kind);
    auto blob = write_track_header(h);
    ASSERT_TRUE(blob.ok()) << blob.status().to_string();
    // Every header starts with the timing fields (SPEC.md §11): frame_count first, little-endian.
    ASSERT_GE(blob->size(), 12u);
    EXPECT_EQ(expected[0].first, "frame_count");
    EXPECT_EQ(std::to_string(load_le(blob->data(), 4)), expected[0].second);
    auto back = read_track_header(kind, *blob, "track");
    ASSERT_TRUE(back.ok()) << back.status().to_string();
    const auto printed = print_track_header(*back);
    ASSERT_EQ(printed.size(), expected.size());
    for (size_t f = 0; f < printed.size(); ++f) {
      EXPECT_EQ(printed[f].name, expected[f].first);
      EXPECT_EQ(printed[f].value, expected[f].second) << printed[f].name;
    }
    // A later minor version's appended bytes are ignored; a short blob is CALF-E051.
    Bytes longer = *blob;
    longer.push_back(0xEE);
    EXPECT_TRUE(read_track_header(kind, longer, "t").ok());
    Bytes shorter(blob->begin(), blob->end() - 1);
    EXPECT_EQ(read_track_header(kind, shorter, "t").status().id(), ErrorId::kContainerTrackHeader);
  }
  EXPECT_TRUE(std::holds_alternative<std::monostate>(*read_track_header(0x7777, Bytes{1}, "t")));
  EXPECT_EQ(write_track_header(TrackHeader{}).status().id(), ErrorId::kContainerWriterMisuse);
}

// A file with one track of every registered kind, filled headers, and one chunk per stream tag,
// then one of an unknown kind (optional or must-understand).
Bytes file_of_every_kind(uint16_t unknown_flags,
                         std::vector<std::vector<std::pair<std::string, std::string>>>* fields) {
  Bytes file;
  auto w = Writer::create(memory_sink(&file));
  EXPECT_TRUE(w.ok());
  for (size_t i = 0; i < std::size(kTrackKinds); ++i) {
    fields->emplace_back();
    const TrackHeader h = filled_header(i, &fields->back());
    auto blob = write_track_header(h);
    auto t = w->add_track(track_header_kind(h), kTrackRequired, *blob);
    EXPECT_TRUE(t.ok());
    for (uint16_t s = 0; s < stream_count(track_header_kind(h)); ++s) {
      ChunkKeys k;
      k.track = *t;
      k.stream = s;
      EXPECT_TRUE(w->add_chunk(k, Bytes(10 + s, 0xAB), Compression::kNone).ok());
    }
  }
  EXPECT_TRUE(w->add_track(0x7777, unknown_flags, Bytes{'n', 'e', 'w'}).ok());
  EXPECT_TRUE(w->finish().ok());
  return file;
}

TEST(TrackRegistry, TheReaderDecodesEveryKindAndSkipsOnlyOptionalUnknownOnes) {
  std::vector<std::vector<std::pair<std::string, std::string>>> fields;
  const Bytes ok_file = file_of_every_kind(0, &fields);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(ok_file)));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r->tracks().size(), std::size(kTrackKinds) + 1);
  for (size_t i = 0; i < std::size(kTrackKinds); ++i) {
    const Track& t = r->tracks()[i];
    EXPECT_TRUE(t.known);
    EXPECT_EQ(track_header_kind(t.header), static_cast<uint16_t>(kTrackKinds[i]));
    EXPECT_EQ(print_track_header(t.header).size(), fields[i].size());
  }
  EXPECT_FALSE(r->tracks().back().known);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(r->tracks().back().header));

  fields.clear();
  const Bytes bad_file = file_of_every_kind(kTrackRequired, &fields);
  auto bad = Reader::open(memory_source(std::span<const uint8_t>(bad_file)));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().id(), ErrorId::kContainerTrackKind);
  EXPECT_NE(bad.status().message().find("kind 30583"), std::string::npos)
      << bad.status().to_string();
}

// calf-info (a build dependency of this test, CALF_INFO_EXE) prints every kind's name, header
// fields and stream names.
TEST(TrackRegistry, CalfInfoPrintsEveryKind) {
  const fs::path exe = CALF_INFO_EXE;
  ASSERT_TRUE(fs::exists(exe)) << exe << " is not built";
  std::vector<std::vector<std::pair<std::string, std::string>>> fields;
  const fs::path dir = fs::temp_directory_path() / ("calf_registry_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto run = [&](const Bytes& file, const std::string& args, std::string* out) {
    const fs::path p = dir / "clip.calf";
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(file.data()),
               static_cast<std::streamsize>(file.size()));
    std::string cmd = "'";
    cmd += exe.string();
    cmd += "' ";
    cmd += args;
    cmd += " '";
    cmd += p.string();
    cmd += "'";
    return testing_support::run_command(cmd, out);
  };
  const Bytes file = file_of_every_kind(0, &fields);
  std::string text, json;
  ASSERT_EQ(run(file, "", &text), 0) << text;
  ASSERT_EQ(run(file, "--json", &json), 0) << json;
  for (size_t i = 0; i < std::size(kTrackKinds); ++i) {
    const auto kind = static_cast<uint16_t>(kTrackKinds[i]);
    const std::string name = track_kind_name(kind);
    SCOPED_TRACE(name);
    const size_t at = text.find("track " + std::to_string(i) + ": " + name + ", must-understand\n");
    ASSERT_NE(at, std::string::npos) << text;
    const size_t end = text.find("\ntrack ", at + 1);
    const std::string block = text.substr(at, end - at);
    for (const auto& [field, value] : fields[i]) {
      // Pixel formats print as "name (number)".
      const bool format = field.size() > 7 && field.ends_with("_format");
      EXPECT_NE(block.find("  " + field + ": " + (format ? "" : value)), std::string::npos)
          << field << " in\n"
          << block;
      if (format) {
        EXPECT_NE(block.find("(" + value + ")"), std::string::npos) << block;
      }
    }
    for (uint16_t s = 0; s < stream_count(kind); ++s)
      EXPECT_NE(block.find(std::string("\n  ") + stream_name(kind, s) + " "), std::string::npos)
          << stream_name(kind, s) << " in\n"
          << block;
    EXPECT_NE(json.find("\"kind\":\"" + name + "\",\"kind_id\":" + std::to_string(kind) +
                        ",\"known\":true"),
              std::string::npos)
        << json;
  }
  EXPECT_NE(text.find(": unknown (kind 30583, skipped)"), std::string::npos) << text;

  fields.clear();
  std::string refused;
  EXPECT_EQ(run(file_of_every_kind(kTrackRequired, &fields), "", &refused), 1) << refused;
  EXPECT_NE(refused.find("CALF-E050"), std::string::npos) << refused;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::container
