#include "json_fields.h"

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <vector>

namespace calf::capture::detail {

namespace {

// A short rendering of an offending value for messages (long values are cut).
std::string describe(const Json& value) {
  std::string text = dump_json(value);
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(value.type_name()) + " " + text;
}

}  // namespace

Expected<Json> parse_json_object(std::string_view text, std::string_view source) {
  Json json;
  try {
    json = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    // e.what() repeats the exception class; the byte offset is what a user needs.
    std::string what = e.what();
    size_t colon = what.rfind(": ");
    return Status(ErrorId::kManifestSyntax,
                  std::string(source) + ": not valid JSON at byte " + std::to_string(e.byte) +
                      (colon == std::string::npos ? "" : ": " + what.substr(colon + 2)));
  } catch (const std::exception& e) {
    return Status(ErrorId::kManifestSyntax, std::string(source) + ": not valid JSON: " + e.what());
  }
  if (!json.is_object()) {
    return Status(ErrorId::kManifestSyntax, std::string(source) + ": the top level is " +
                                                json.type_name() + ", expected a JSON object");
  }
  return json;
}

std::string dump_json(const Json& json) {
  return json.dump(2, ' ', false, Json::error_handler_t::replace);
}

Status FieldReader::error(ErrorId id, const std::string& field_path,
                          const std::string& what) const {
  return Status(id, std::string(source_) + ": field '" + field_path + "': " + what);
}

Status FieldReader::check_keys(std::initializer_list<const char*> allowed) const {
  for (const auto& item : object_.items()) {
    const std::string& key = item.key();
    if (key.rfind("x-", 0) == 0) continue;
    bool known =
        std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; });
    if (!known) return error(field(key.c_str()), "unknown key (extensions must start with \"x-\")");
  }
  return Status::Ok();
}

Expected<const Json*> FieldReader::get(const char* key) const {
  auto it = object_.find(key);
  if (it == object_.end()) return error(field(key), "missing");
  return &*it;
}

Expected<double> FieldReader::number(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_number()) return error(field(key), "expected a number, got " + describe(*v));
  double d = v->get<double>();
  if (!std::isfinite(d)) return error(value_id_, field(key), "expected a finite number");
  return d;
}

Expected<uint64_t> FieldReader::count(const char* key, uint64_t max) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  const bool negative = v->is_number_integer() && !v->is_number_unsigned() && v->get<int64_t>() < 0;
  if (!v->is_number_integer() || negative)
    return error(field(key), "expected an integer >= 0, got " + describe(*v));
  const uint64_t u = v->get<uint64_t>();
  if (u > max) {
    return error(limit_id_, field(key),
                 std::to_string(u) + " exceeds the limit of " + std::to_string(max));
  }
  return u;
}

// JSON numbers go through double; a value beyond float's range would become inf, so it is refused
// as not finite.
Expected<float> FieldReader::f32(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_number()) return error(field(key), "expected a number, got " + describe(*v));
  const double d = v->get<double>();
  if (!std::isfinite(d) || std::fabs(d) > FLT_MAX)
    return error(value_id_, field(key), "is not a finite 32-bit float");
  return static_cast<float>(d);
}

Expected<std::array<float, 3>> FieldReader::float3(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_array() || v->size() != 3)
    return error(field(key), "expected [x, y, z], got " + describe(*v));
  std::array<float, 3> out{};
  for (size_t i = 0; i < 3; ++i) {
    const Json& e = (*v)[i];
    const std::string at = field(key) + "[" + std::to_string(i) + "]";
    if (!e.is_number()) return error(at, "expected a number, got " + describe(e));
    const double d = e.get<double>();
    if (!std::isfinite(d) || std::fabs(d) > FLT_MAX)
      return error(value_id_, at, "is not a finite 32-bit float");
    out[i] = static_cast<float>(d);
  }
  return out;
}

Expected<const Json*> FieldReader::array(const char* key, size_t max) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_array()) return error(field(key), "expected an array, got " + describe(*v));
  if (v->size() > max) {
    return error(limit_id_, field(key),
                 std::to_string(v->size()) + " entries exceed the limit of " + std::to_string(max));
  }
  return v;
}

Expected<uint32_t> FieldReader::uint(const char* key, uint32_t min, uint32_t max) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_number_integer()) {
    return error(field(key), "expected an integer, got " + describe(*v));
  }
  // Compare in a wide signed type so that -1 and 2^40 are both reported, not wrapped.
  bool negative = v->is_number_integer() && !v->is_number_unsigned() && v->get<int64_t>() < 0;
  uint64_t u = negative ? 0 : v->get<uint64_t>();
  if (negative || u < min || u > max) {
    return error(field(key), "value " + dump_json(*v) + " is outside [" + std::to_string(min) +
                                 ", " + std::to_string(max) + "]");
  }
  return static_cast<uint32_t>(u);
}

Expected<std::string> FieldReader::string(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_string()) return error(field(key), "expected a string, got " + describe(*v));
  return v->get<std::string>();
}

Expected<bool> FieldReader::boolean(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_boolean()) return error(field(key), "expected true or false, got " + describe(*v));
  return v->get<bool>();
}

Expected<Vec3> FieldReader::point(const char* key) const {
  CALF_ASSIGN_OR_RETURN(const Json* v, get(key));
  if (!v->is_array() || v->size() != 3) {
    return error(field(key), "expected [x, y, z], got " + describe(*v));
  }
  double c[3];
  for (size_t i = 0; i < 3; ++i) {
    const Json& e = (*v)[i];
    const std::string at = field(key) + "[" + std::to_string(i) + "]";
    if (!e.is_number()) return error(at, "expected a finite number, got " + describe(e));
    if (!std::isfinite(e.get<double>()))
      return error(value_id_, at, "expected a finite number, got " + describe(e));
    c[i] = e.get<double>();
  }
  return Vec3{c[0], c[1], c[2]};
}

Expected<double> FieldReader::number_or(const char* key, double fallback) const {
  return has(key) ? number(key) : Expected<double>(fallback);
}

Expected<std::string> FieldReader::string_or(const char* key, std::string fallback) const {
  return has(key) ? string(key) : Expected<std::string>(std::move(fallback));
}

Expected<bool> FieldReader::boolean_or(const char* key, bool fallback) const {
  return has(key) ? boolean(key) : Expected<bool>(fallback);
}

Expected<float> FieldReader::f32_or(const char* key, float fallback) const {
  return has(key) ? f32(key) : Expected<float>(fallback);
}

Expected<std::array<float, 3>> FieldReader::float3_or(const char* key,
                                                      std::array<float, 3> fallback) const {
  return has(key) ? float3(key) : Expected<std::array<float, 3>>(fallback);
}

Expected<const Json*> FieldReader::array_or_null(const char* key, size_t max) const {
  return has(key) ? array(key, max) : Expected<const Json*>(nullptr);
}

namespace {

// One "{...}" token of a pattern.
struct Token {
  size_t begin = 0, end = 0;  // [begin, end) in the pattern, braces included
  std::string name;
  int width = 0;  // 0: no padding
};

// Splits out the tokens; returns a problem description or "".
std::string scan_tokens(std::string_view pattern, std::vector<Token>* tokens) {
  for (size_t i = 0; i < pattern.size(); ++i) {
    char c = pattern[i];
    if (c == '}') return "'}' without '{' at offset " + std::to_string(i);
    if (c != '{') {
      bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '_' || c == '-' || c == '.';
      if (!ok) return "character '" + std::string(1, c) + "' is not allowed in a file name";
      continue;
    }
    size_t close = pattern.find('}', i);
    if (close == std::string_view::npos) return "'{' without '}'";
    std::string_view inner = pattern.substr(i + 1, close - i - 1);
    Token t{i, close + 1, std::string(inner), 0};
    size_t colon = inner.find(':');
    if (colon != std::string_view::npos) {
      std::string_view spec = inner.substr(colon + 1);
      if (spec.size() != 2 || spec[0] != '0' || spec[1] < '1' || spec[1] > '9') {
        return "token '{" + std::string(inner) + "}' must be {name} or {name:0N} with N in 1..9";
      }
      t.name = std::string(inner.substr(0, colon));
      t.width = spec[1] - '0';
    }
    tokens->push_back(t);
    i = close;
  }
  return "";
}

}  // namespace

std::string expand_pattern_token(std::string_view pattern, std::string_view token, uint32_t value) {
  std::vector<Token> tokens;
  if (!scan_tokens(pattern, &tokens).empty()) return std::string(pattern);
  std::string out;
  size_t at = 0;
  for (const Token& t : tokens) {
    out.append(pattern.substr(at, t.begin - at));
    if (t.name == token) {
      char buf[24];
      std::snprintf(buf, sizeof buf, "%0*u", t.width, value);
      out += buf;
    } else {
      out.append(pattern.substr(t.begin, t.end - t.begin));
    }
    at = t.end;
  }
  out.append(pattern.substr(at));
  return out;
}

std::string pattern_problem(std::string_view pattern,
                            std::initializer_list<std::string_view> names) {
  if (pattern.empty()) return "empty";
  if (pattern.size() > 200) return "longer than 200 characters";
  if (pattern[0] == '.') return "starts with '.'";
  if (pattern.size() < 4 || pattern.substr(pattern.size() - 4) != ".exr") {
    return "does not end in \".exr\"";
  }
  std::vector<Token> tokens;
  if (std::string problem = scan_tokens(pattern, &tokens); !problem.empty()) return problem;
  for (std::string_view name : names) {
    long count =
        std::count_if(tokens.begin(), tokens.end(), [&](const Token& t) { return t.name == name; });
    if (count != 1) return "must hold {" + std::string(name) + "} exactly once";
  }
  if (tokens.size() != names.size()) return "holds an unknown token";
  for (size_t i = 1; i < tokens.size(); ++i) {
    std::string_view between =
        pattern.substr(tokens[i - 1].end, tokens[i].begin - tokens[i - 1].end);
    bool separated =
        std::any_of(between.begin(), between.end(), [](char c) { return c < '0' || c > '9'; });
    if (!separated) return "needs a non-digit character between two tokens";
  }
  return "";
}

}  // namespace calf::capture::detail
