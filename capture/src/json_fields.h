// Typed, validating access to JSON fields for the capture layer's JSON files (internal): the
// manifest, eye-path, Seurat and equirectangular manifests and the scene file.
// Every error names the source file and the field's path ("viewpoints[3].position[1]"), and
// nothing here throws: nlohmann is only asked for values whose type was checked first.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "calf/capture/capture_set.h"
#include "calf/format/status.h"

namespace calf::capture::detail {

using Json = nlohmann::json;

// Parses JSON text; E130 with the byte offset on a syntax error, or when the root is not an
// object.
Expected<Json> parse_json_object(std::string_view text, std::string_view source);

// JSON text without exceptions: invalid UTF-8 in strings is replaced, never thrown.
std::string dump_json(const Json& json);

// Reads the fields of one JSON object, reporting errors as "<source>: field '<path>.<key>':
// <what>" with `id`, or with `limit_id` for a count or array beyond its limit and `value_id` for a
// number that is not finite (or beyond a float's range); both are `id` unless given.
class FieldReader {
 public:
  FieldReader(const Json& object, std::string path, std::string_view source, ErrorId id)
      : FieldReader(object, std::move(path), source, id, id, id) {}
  FieldReader(const Json& object, std::string path, std::string_view source, ErrorId id,
              ErrorId limit_id, ErrorId value_id)
      : object_(object),
        path_(std::move(path)),
        source_(source),
        id_(id),
        limit_id_(limit_id),
        value_id_(value_id) {}

  // E(id) when the object has a key outside `allowed` (keys starting "x-" are extensions and
  // always allowed), so that a misspelt optional field is an error and not silently ignored.
  Status check_keys(std::initializer_list<const char*> allowed) const;

  bool has(const char* key) const { return object_.contains(key); }
  // The full path of a key, for messages: "viewpoints[2].name".
  std::string field(const char* key) const { return path_.empty() ? key : path_ + "." + key; }
  Status error(const std::string& field_path, const std::string& what) const {
    return error(id_, field_path, what);
  }
  Status error(ErrorId id, const std::string& field_path, const std::string& what) const;

  Expected<const Json*> get(const char* key) const;
  Expected<double> number(const char* key) const;  // finite
  Expected<uint32_t> uint(const char* key, uint32_t min, uint32_t max) const;
  // An integer >= 0; above `max` the limit id.
  Expected<uint64_t> count(const char* key, uint64_t max) const;
  // A number that is finite as a 32-bit float (the value id otherwise).
  Expected<float> f32(const char* key) const;
  // [x, y, z] of such floats.
  Expected<std::array<float, 3>> float3(const char* key) const;
  // An array of at most `max` entries (the limit id beyond).
  Expected<const Json*> array(const char* key, size_t max) const;
  Expected<std::string> string(const char* key) const;
  Expected<bool> boolean(const char* key) const;
  Expected<Vec3> point(const char* key) const;  // [x, y, z], finite
  // Optional forms: `fallback` when the key is absent.
  Expected<double> number_or(const char* key, double fallback) const;
  Expected<std::string> string_or(const char* key, std::string fallback) const;
  Expected<bool> boolean_or(const char* key, bool fallback) const;
  Expected<float> f32_or(const char* key, float fallback) const;
  Expected<std::array<float, 3>> float3_or(const char* key, std::array<float, 3> fallback) const;
  // nullptr when absent.
  Expected<const Json*> array_or_null(const char* key, size_t max) const;

  std::string_view source() const { return source_; }
  ErrorId id() const { return id_; }

 private:
  const Json& object_;
  std::string path_;
  std::string_view source_;
  ErrorId id_, limit_id_, value_id_;
};

// Vec3 as a JSON array [x, y, z].
inline Json point_json(const Vec3& p) {
  return Json::array({p.x, p.y, p.z});
}

// Expands a file pattern with one token named `token` ("view", "frame", "pose"): "{name}" gives
// the decimal value, "{name:0N}" pads it with zeros to N digits (N in 1..9).
std::string expand_pattern_token(std::string_view pattern, std::string_view token, uint32_t value);

// Checks a file pattern: a plain file name (no directory separators, no leading '.', characters
// A-Z a-z 0-9 _ - . and the tokens), ending in ".exr", holding each of `tokens` exactly once in a
// well-formed "{name}" / "{name:0N}" form, with at least one non-digit character between two
// tokens (so that no two index combinations give the same name). Returns a description of the
// first problem, or "" when the pattern is valid.
std::string pattern_problem(std::string_view pattern,
                            std::initializer_list<std::string_view> tokens);

}  // namespace calf::capture::detail
