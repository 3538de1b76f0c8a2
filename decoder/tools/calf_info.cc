// calf-info: an ffprobe-like summary of a .calf clip: version, tracks (kind, frames, fps, views,
// face size, formats, and the figures of its kind's entry in the decoder table,
// calf/decoder/kind_table.h: a mesh track's objects, prototypes and triangles, ...), metadata,
// and bytes per stream with the ratio to raw. --json prints the same as one JSON object;
// --chunks adds the chunk index. Reads only the header and directory.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <map>
#include <optional>
#include <string>

#include "calf/decoder/kind_table.h"
#include "calf/format/container.h"
#include "command_line.h"

namespace {

using namespace calf::container;

// JSON string literal; metadata is validated UTF-8, so only escapes are needed.
std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Metadata for a terminal: control characters (C0, DEL, and C1 as UTF-8, which terminals act on
// too) are shown as \xNN / \u00NN, so a clip cannot send escape sequences to the terminal.
std::string printable(std::string_view s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned>(c));
    } else if (c == 0xc2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(s[i + 1]) <= 0x9f) {
      out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(s[++i])));
    } else {
      out += s[i];
    }
  }
  return out;
}

struct StreamStats {
  uint64_t chunks = 0, stored = 0, raw = 0;
};

std::string ratio(const StreamStats& s) {
  return s.stored ? fmt::format("{:.3f}", static_cast<double>(s.raw) / s.stored) : "0";
}

// A track header field's value for people: formats by name.
std::string field_text(const FieldPrinter::Entry& e) {
  if (e.name.size() > 7 && e.name.compare(e.name.size() - 7, 7, "_format") == 0)
    return fmt::format("{} ({})", pixel_format_name(static_cast<uint16_t>(std::stoul(e.value))),
                       e.value);
  return e.value;
}

// The track's header fields through the registry (none for a kind it lacks).
std::vector<FieldPrinter::Entry> header_fields(const Track& t) {
  return print_track_header(t.header);
}

std::map<uint16_t, StreamStats> stream_stats(const Reader& r, uint16_t track) {
  std::map<uint16_t, StreamStats> out;
  for (const auto& c : r.chunks()) {
    if (c.keys.track != track) continue;
    auto& s = out[c.keys.stream];
    ++s.chunks;
    s.stored += c.stored_size;
    s.raw += c.raw_size;
  }
  return out;
}

// The track's summary figures through its kind's entry in the decoder table (none for a kind it
// lacks or a kind without figures).
std::optional<calf::decoder::TrackFigures> figures(const Reader& r, const Track& t) {
  const auto* kind = calf::decoder::find_decoder_kind(t.record.kind);
  if (kind == nullptr || kind->figures == nullptr) return std::nullopt;
  return kind->figures(r, t);
}

bool compressed_directory(const FileHeader& h) {
  return (h.required_features & kFeatureCompressedDirectory) != 0;
}
// Zero bytes that align chunks to 16 (SPEC §7): the chunk area less the stored bytes.
uint64_t padding_bytes(const Reader& r, const StreamStats& total) {
  return r.header().directory_offset - kHeaderSize - total.stored;
}

void print_text(const std::string& path, const Reader& r, bool list_chunks) {
  const auto& h = r.header();
  StreamStats total;
  for (const auto& c : r.chunks()) total.stored += c.stored_size, total.raw += c.raw_size;
  fmt::print("{}: calf container {}.{}, {} bytes, {} tracks, {} chunks\n", path, h.version_major,
             h.version_minor, h.file_size, r.tracks().size(), r.chunks().size());
  fmt::print("  payload: {} stored bytes, {} raw bytes, ratio {}\n", total.stored, total.raw,
             ratio(total));
  fmt::print("  directory: {} bytes ({}), padding: {} bytes\n", h.directory_size,
             compressed_directory(h)
                 ? fmt::format("zstd, {} bytes of index and metadata", r.directory_body_size())
                 : std::string("plain"),
             padding_bytes(r, total));
  if (!r.metadata().empty()) fmt::print("metadata:\n");
  for (const auto& m : r.metadata())
    fmt::print("  {} = {}\n", printable(m.key), printable(m.value));
  for (const auto& t : r.tracks()) {
    fmt::print("track {}: {}{}{}\n", t.id, track_kind_name(t.record.kind),
               t.known ? "" : fmt::format(" (kind {}, skipped)", t.record.kind),
               (t.record.flags & kTrackRequired) ? ", must-understand" : "");
    const auto fields = header_fields(t);
    uint64_t frames = 0, num = 0, den = 0;
    for (const auto& e : fields) {
      if (e.name == "frame_count") frames = std::stoull(e.value);
      if (e.name == "fps_numerator") num = std::stoull(e.value);
      if (e.name == "fps_denominator") den = std::stoull(e.value);
    }
    if (num && den)
      fmt::print("  {} frames at {:.3f} fps ({}/{}), {:.3f} s\n", frames,
                 static_cast<double>(num) / den, num, den, static_cast<double>(frames) * den / num);
    for (const auto& e : fields) fmt::print("  {}: {}\n", e.name, printable(field_text(e)));
    if (const auto f = figures(r, t)) fmt::print("  {}\n", f->text);
    fmt::print("  {:<12} {:>8} {:>14} {:>14} {:>8}\n", "stream", "chunks", "stored bytes",
               "raw bytes", "ratio");
    for (const auto& [tag, s] : stream_stats(r, t.id)) {
      const char* name = stream_name(t.record.kind, tag);
      fmt::print("  {:<12} {:>8} {:>14} {:>14} {:>8}\n",
                 *name ? fmt::format("{}", name) : fmt::format("stream {}", tag), s.chunks,
                 s.stored, s.raw, ratio(s));
    }
  }
  if (list_chunks) {
    fmt::print(
        "chunks: id offset stored raw compression track stream view face region layer "
        "first_frame frame_count hash\n");
    for (size_t i = 0; i < r.chunks().size(); ++i) {
      const auto& c = r.chunks()[i];
      fmt::print("  {} {} {} {} {} {} {} {} {} {} {} {} {} {:016x}\n", i, c.offset, c.stored_size,
                 c.raw_size, compression_name(Compression(c.compression)), c.keys.track,
                 c.keys.stream, c.keys.view, c.keys.face, c.keys.region, c.keys.layer,
                 c.keys.first_frame, c.keys.frame_count, c.hash);
    }
  }
}

void print_json(const std::string& path, const Reader& r, bool list_chunks) {
  const auto& h = r.header();
  StreamStats total;
  for (const auto& c : r.chunks()) total.stored += c.stored_size, total.raw += c.raw_size;
  std::string o = "{";
  o += fmt::format("\"file\":{},\"version\":\"{}.{}\",\"file_size\":{},", json_string(path),
                   h.version_major, h.version_minor, h.file_size);
  o += fmt::format("\"required_features\":{},\"optional_features\":{},", h.required_features,
                   h.optional_features);
  o += fmt::format("\"chunk_count\":{},\"stored_bytes\":{},\"raw_bytes\":{},\"ratio\":{},",
                   r.chunks().size(), total.stored, total.raw, ratio(total));
  o += fmt::format(
      "\"directory_bytes\":{},\"directory_compressed\":{},\"directory_body_bytes\":{},"
      "\"padding_bytes\":{},",
      h.directory_size, compressed_directory(h), r.directory_body_size(), padding_bytes(r, total));
  o += "\"metadata\":{";
  for (size_t i = 0; i < r.metadata().size(); ++i)
    o += fmt::format("{}{}:{}", i ? "," : "", json_string(r.metadata()[i].key),
                     json_string(r.metadata()[i].value));
  o += "},\"tracks\":[";
  for (const auto& t : r.tracks()) {
    o += fmt::format("{}{{\"id\":{},\"kind\":{},\"kind_id\":{},\"known\":{},\"required\":{},",
                     t.id ? "," : "", t.id, json_string(track_kind_name(t.record.kind)),
                     t.record.kind, t.known, (t.record.flags & kTrackRequired) != 0);
    o += "\"header\":{";
    const auto fields = header_fields(t);
    for (size_t i = 0; i < fields.size(); ++i)
      o += fmt::format("{}{}:{}", i ? "," : "", json_string(fields[i].name),
                       fields[i].numeric ? fields[i].value : json_string(fields[i].value));
    o += "}";
    if (const auto f = figures(r, t)) o += "," + f->json;
    o += ",\"streams\":[";
    bool first = true;
    for (const auto& [tag, s] : stream_stats(r, t.id)) {
      o += fmt::format(
          "{}{{\"stream\":{},\"name\":{},\"chunks\":{},\"stored_bytes\":{},"
          "\"raw_bytes\":{},\"ratio\":{}}}",
          first ? "" : ",", tag, json_string(stream_name(t.record.kind, tag)), s.chunks, s.stored,
          s.raw, ratio(s));
      first = false;
    }
    o += "]}";
  }
  o += "]";
  if (list_chunks) {
    o += ",\"chunks\":[";
    for (size_t i = 0; i < r.chunks().size(); ++i) {
      const auto& c = r.chunks()[i];
      o += fmt::format(
          "{}{{\"id\":{},\"offset\":{},\"stored_size\":{},\"raw_size\":{},\"compression\":{},"
          "\"track\":{},\"stream\":{},\"view\":{},\"face\":{},\"region\":{},\"layer\":{},"
          "\"first_frame\":{},\"frame_count\":{},\"hash\":\"{:016x}\"}}",
          i ? "," : "", i, c.offset, c.stored_size, c.raw_size,
          json_string(compression_name(Compression(c.compression))), c.keys.track, c.keys.stream,
          c.keys.view, c.keys.face, c.keys.region, c.keys.layer, c.keys.first_frame,
          c.keys.frame_count, c.hash);
    }
    o += "]";
  }
  fmt::print("{}}}\n", o);
}

}  // namespace

static int command_main(int argc, char** argv) {
  CLI::App app{
      std::string("calf-info: summarise a .calf clip (version, tracks, frames, views, face size, "
                  "formats, bytes per stream and ratio to raw). Reads only the header and "
                  "directory; use calf-verify to check every chunk. Control characters in "
                  "metadata are printed escaped (\\xNN) in text mode.\n") +
      calf::tools::kExitStatusHelp};
  std::string path;
  bool json = false, chunks = false;
  app.add_option("FILE", path, "the .calf clip (a regular file)")->required();
  app.add_flag("--json", json, "print one JSON object instead of text");
  app.add_flag("--chunks", chunks, "also list every chunk index entry");
  if (int rc = calf::tools::parse_command_line(app, "calf-info", argc, argv); rc >= 0) return rc;
  // Reader::open's errors name the file once.
  auto reader = Reader::open(path);
  if (!reader.ok()) return calf::tools::print_error("calf-info", reader.status());
  if (json)
    print_json(path, *reader, chunks);
  else
    print_text(path, *reader, chunks);
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-info", [&] { return command_main(argc, argv); });
}
