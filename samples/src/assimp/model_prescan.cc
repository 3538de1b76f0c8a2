// Cheap checks of a model file before assimp reads it (model_prescan.h).
#include "model_prescan.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

namespace calf::samples::detail {

namespace {

using Json = nlohmann::json;

constexpr uint64_t kMaxPlyHeader = 1 << 20;
// An accessor without a buffer view (all zeros, or sparse) holds no bytes of its own; assimp
// still allocates count * element size for it.
constexpr double kMaxImplicitAccessorBytes = 64.0 * (1 << 20);

Status declared(std::string_view name, const std::string& what) {
  return Status(ErrorId::kSceneLoad, std::string(name) + ": " + what);
}

// ---- PLY ---------------------------------------------------------------------------------------

// Bytes of one PLY scalar type; 0 when the name is not a PLY type.
uint64_t ply_type_size(std::string_view t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" ||
      t == "float32") {
    return 4;
  }
  if (t == "double" || t == "float64") return 8;
  return 0;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && (line[at] == ' ' || line[at] == '\t' || line[at] == '\r')) ++at;
    size_t end = at;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r') ++end;
    if (end > at) words.push_back(line.substr(at, end - at));
    at = end;
  }
  return words;
}

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  uint64_t properties = 0;
  uint64_t min_binary_bytes = 0;  // scalars plus list counts (every list may be empty)
};

// ---- glTF --------------------------------------------------------------------------------------

bool starts_with_nocase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (size_t i = 0; i < prefix.size(); ++i) {
    char c = s[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c != prefix[i]) return false;
  }
  return true;
}

// What one URI refers to: embedded bytes (data:) or a relative file inside the folder.
struct UriTarget {
  bool embedded = false;
  uint64_t embedded_bytes = 0;  // an upper bound on the decoded payload
  std::filesystem::path file;   // relative, normalised
};

Expected<UriTarget> check_uri(const std::string& uri, std::string_view name,
                              const std::string& field) {
  UriTarget target;
  auto refuse = [&](const std::string& why) {
    return Status(ErrorId::kSceneLoad,
                  std::string(name) + ": " + field + " \"" + uri.substr(0, 200) + "\" " + why);
  };
  if (starts_with_nocase(uri, "data:")) {
    target.embedded = true;
    size_t comma = uri.find(',');
    uint64_t payload = comma == std::string::npos ? 0 : uri.size() - comma - 1;
    bool base64 = comma != std::string::npos && uri.rfind(";base64", comma) != std::string::npos;
    target.embedded_bytes = base64 ? payload / 4 * 3 + 3 : payload;
    return target;
  }
  const std::string path = percent_decode(uri);
  if (path.empty()) return refuse("is empty");
  if (path.find('\0') != std::string::npos) return refuse("holds a NUL byte");
  size_t colon = path.find(':');
  if (colon != std::string::npos && path.find_first_of("/\\") > colon) {
    return refuse("has a scheme or drive (only data: URIs and relative paths are read)");
  }
  if (path[0] == '/' || path[0] == '\\') return refuse("is an absolute path");
  int depth = 0;
  std::filesystem::path normal;
  size_t at = 0;
  while (at <= path.size()) {
    size_t end = path.find_first_of("/\\", at);
    if (end == std::string::npos) end = path.size();
    std::string part = path.substr(at, end - at);
    if (part == "..") {
      if (--depth < 0) return refuse("leaves the model's folder");
      normal = normal.parent_path();
    } else if (!part.empty() && part != ".") {
      ++depth;
      normal /= part;
    }
    at = end + 1;
  }
  target.file = normal;
  return target;
}

// A non-negative JSON number as double, or -1 when absent or of another type (assimp reports
// those itself).
double number_field(const Json& object, const char* key) {
  if (!object.is_object()) return -1;
  auto it = object.find(key);
  if (it == object.end() || !it->is_number()) return -1;
  double v = it->get<double>();
  return v >= 0 ? v : -1;
}

// A reference to another element: an array index (glTF 2) or an object key (glTF 1).
std::string reference(const Json& object, const char* key) {
  if (!object.is_object()) return "";
  auto it = object.find(key);
  if (it == object.end()) return "";
  if (it->is_number_unsigned()) return std::to_string(it->get<uint64_t>());
  if (it->is_string()) return it->get<std::string>();
  return "";
}

// Every element of a glTF collection with its id: index for arrays, key for objects.
std::vector<std::pair<std::string, const Json*>> elements(const Json& root, const char* key) {
  std::vector<std::pair<std::string, const Json*>> out;
  auto it = root.find(key);
  if (it == root.end()) return out;
  if (it->is_array()) {
    for (size_t i = 0; i < it->size(); ++i) out.emplace_back(std::to_string(i), &(*it)[i]);
  } else if (it->is_object()) {
    for (auto e = it->begin(); e != it->end(); ++e) out.emplace_back(e.key(), &e.value());
  }
  return out;
}

uint64_t component_bytes(double type) {
  if (type == 5120 || type == 5121) return 1;
  if (type == 5122 || type == 5123) return 2;
  if (type == 5124 || type == 5125 || type == 5126) return 4;
  return 1;
}

uint64_t component_count(const Json& accessor) {
  auto it = accessor.find("type");
  if (it == accessor.end() || !it->is_string()) return 1;
  const std::string& t = it->get_ref<const std::string&>();
  if (t == "VEC2") return 2;
  if (t == "VEC3") return 3;
  if (t == "VEC4" || t == "MAT2") return 4;
  if (t == "MAT3") return 9;
  if (t == "MAT4") return 16;
  return 1;
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

uint32_t le32(const char* p) {
  uint32_t v = 0;
  std::memcpy(&v, p, 4);  // GLB is little-endian, like every machine calf builds on
  return v;
}

}  // namespace

std::string percent_decode(std::string_view s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    auto hex = [](char c) {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    if (s[i] == '%' && i + 2 < s.size() && hex(s[i + 1]) >= 0 && hex(s[i + 2]) >= 0) {
      out.push_back(static_cast<char>(hex(s[i + 1]) * 16 + hex(s[i + 2])));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

Status prescan_ply(std::string_view head, uint64_t file_size, std::string_view name) {
  const std::string file(name);
  auto malformed = [&](const std::string& why) {
    return Status(ErrorId::kSceneLoad, file + ": PLY header: " + why);
  };
  if (head.substr(0, 3) != "ply") return malformed("no 'ply' magic");
  std::vector<PlyElement> elements;
  bool ascii = true;
  size_t at = 0;
  size_t header_end = std::string_view::npos;
  while (at < head.size()) {
    size_t nl = head.find('\n', at);
    if (nl == std::string_view::npos) break;
    std::vector<std::string_view> w = split_words(head.substr(at, nl - at));
    at = nl + 1;
    if (w.empty()) continue;
    if (w[0] == "end_header") {
      header_end = at;
      break;
    }
    if (w[0] == "format" && w.size() >= 2) {
      ascii = w[1] == "ascii";
    } else if (w[0] == "element" && w.size() >= 3) {
      PlyElement e;
      e.name = std::string(w[1].substr(0, 64));
      const std::string_view digits = w[2];
      if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos) {
        return malformed("element '" + e.name + "' has count '" +
                         std::string(digits.substr(0, 32)) + "'");
      }
      for (char c : digits) {
        if (e.count > (std::numeric_limits<uint64_t>::max() - 9) / 10) {
          return declared(name, "PLY element '" + e.name + "' declares a count of " +
                                    std::to_string(digits.size()) + " digits");
        }
        e.count = e.count * 10 + static_cast<uint64_t>(c - '0');
      }
      elements.push_back(std::move(e));
    } else if (w[0] == "property" && !elements.empty()) {
      PlyElement& e = elements.back();
      ++e.properties;
      if (w.size() >= 2 && w[1] == "list") {
        e.min_binary_bytes += w.size() >= 3 ? std::max<uint64_t>(1, ply_type_size(w[2])) : 1;
      } else {
        e.min_binary_bytes += w.size() >= 2 ? std::max<uint64_t>(1, ply_type_size(w[1])) : 1;
      }
    }
  }
  if (header_end == std::string_view::npos) {
    return malformed("no end_header line in the first " + std::to_string(head.size()) + " bytes");
  }
  // Every row of an element takes at least one byte per property (a one-digit value, or the
  // smallest binary size of each property), and at least one byte even with no property; so the
  // declared rows must fit in the bytes after the header.
  const uint64_t body = file_size > header_end ? file_size - header_end : 0;
  uint64_t needed = 0;
  for (const PlyElement& e : elements) {
    uint64_t row = std::max<uint64_t>(1, ascii ? e.properties : e.min_binary_bytes);
    if (e.count > (body - std::min(body, needed)) / row) {
      return declared(name, "PLY element '" + e.name + "' declares " + std::to_string(e.count) +
                                " rows of at least " + std::to_string(row) + " bytes, but " +
                                std::to_string(body) + " bytes follow the header");
    }
    needed += e.count * row;
  }
  return Status::Ok();
}

Status prescan_gltf_json(std::string_view json, std::string_view name,
                         const std::filesystem::path& folder, uint64_t glb_bin_bytes,
                         bool has_glb_bin) {
  Json root = Json::parse(json.begin(), json.end(), nullptr, false);
  // Not JSON, or not an object: assimp reports it (E171).
  if (root.is_discarded() || !root.is_object()) return Status::Ok();

  // URIs first: nothing outside the folder is even looked at.
  std::map<std::string, double> buffer_bytes;  // declared byteLength per buffer id
  double total_buffer_bytes = 0;
  for (const char* collection : {"buffers", "images", "shaders"}) {
    for (const auto& [id, element] : elements(root, collection)) {
      const std::string field = std::string(collection) + "[" + id + "].uri";
      UriTarget target;
      bool has_uri = false;
      if (element->is_object()) {
        auto uri = element->find("uri");
        if (uri != element->end() && uri->is_string()) {
          CALF_ASSIGN_OR_RETURN(target, check_uri(uri->get<std::string>(), name, field));
          has_uri = true;
        }
      }
      if (std::string_view(collection) != "buffers") continue;
      // What the buffer really holds: its data: payload, its file, or the GLB binary chunk.
      double actual = 0;
      if (has_uri && target.embedded) {
        actual = static_cast<double>(target.embedded_bytes);
      } else if (has_uri) {
        std::error_code ec;
        std::filesystem::path file = folder / target.file;
        if (!std::filesystem::is_regular_file(file, ec)) continue;  // assimp reports it missing
        actual = static_cast<double>(std::filesystem::file_size(file, ec));
        if (ec) continue;
      } else if (has_glb_bin) {
        actual = static_cast<double>(glb_bin_bytes);
      }
      double length = number_field(*element, "byteLength");
      if (length < 0) length = 0;
      if (length > actual) {
        return declared(name, "buffers[" + id + "].byteLength " + number_text(length) +
                                  " exceeds the " + number_text(actual) + " bytes it holds");
      }
      buffer_bytes[id] = length;
      total_buffer_bytes += length;
    }
  }
  std::map<std::string, double> view_bytes;
  for (const auto& [id, view] : elements(root, "bufferViews")) {
    double offset = std::max(0.0, number_field(*view, "byteOffset"));
    double length = std::max(0.0, number_field(*view, "byteLength"));
    auto buffer = buffer_bytes.find(reference(*view, "buffer"));
    if (buffer == buffer_bytes.end()) continue;  // assimp reports a bad reference
    if (offset + length > buffer->second) {
      return declared(name, "bufferViews[" + id + "] ends at byte " + number_text(offset + length) +
                                ", beyond its buffer's " + number_text(buffer->second) + " bytes");
    }
    view_bytes[id] = length;
  }
  for (const auto& [id, accessor] : elements(root, "accessors")) {
    if (!accessor->is_object()) continue;
    double count = std::max(0.0, number_field(*accessor, "count"));
    double offset = std::max(0.0, number_field(*accessor, "byteOffset"));
    double element = static_cast<double>(component_bytes(number_field(*accessor, "componentType")) *
                                         component_count(*accessor));
    double bytes = count * element;
    // Elements are at least `element` bytes apart (a stride below that is invalid), so they
    // need count * element bytes of their view.
    auto view = view_bytes.find(reference(*accessor, "bufferView"));
    if (view != view_bytes.end()) {
      if (offset + bytes > view->second) {
        return declared(name, "accessors[" + id + "] declares " + number_text(count) +
                                  " elements of " + number_text(element) + " bytes from byte " +
                                  number_text(offset) + " of a " + number_text(view->second) +
                                  "-byte buffer view");
      }
    } else if (bytes > kMaxImplicitAccessorBytes + total_buffer_bytes) {
      return declared(name, "accessors[" + id + "] declares " + number_text(count) + " elements (" +
                                number_text(bytes) +
                                " bytes) without the buffer data to hold them");
    }
  }
  return Status::Ok();
}

Status prescan_glb(std::string_view bytes, std::string_view name,
                   const std::filesystem::path& folder) {
  if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF") return Status::Ok();  // assimp decides
  const uint32_t version = le32(bytes.data() + 4);
  const uint32_t length = le32(bytes.data() + 8);
  if (length > bytes.size()) {
    return declared(name, "GLB header declares " + std::to_string(length) +
                              " bytes, the file has " + std::to_string(bytes.size()));
  }
  if (length < 20) {
    return declared(name, "GLB header declares " + std::to_string(length) +
                              " bytes, less than its own headers");
  }
  const std::string_view file = bytes.substr(0, length);
  if (version == 1) {
    // glTF 1 binary: content length and format, the JSON, then the "binary_glTF" body.
    const uint64_t json_length = le32(file.data() + 12);
    if (json_length > file.size() - 20) {
      return declared(name,
                      "GLB content length " + std::to_string(json_length) + " exceeds the file");
    }
    return prescan_gltf_json(file.substr(20, json_length), name, folder,
                             file.size() - 20 - json_length, true);
  }
  // glTF 2: chunks of (length, type, data); JSON first, then an optional BIN chunk.
  const uint64_t json_length = le32(file.data() + 12);
  if (json_length > file.size() - 20) {
    return declared(name,
                    "GLB JSON chunk length " + std::to_string(json_length) + " exceeds the file");
  }
  const std::string_view json = file.substr(20, json_length);
  uint64_t bin = 0;
  bool has_bin = false;
  const uint64_t next = 20 + ((json_length + 3) & ~uint64_t{3});
  if (next + 8 <= file.size()) {
    const uint64_t bin_length = le32(file.data() + next);
    if (bin_length > file.size() - next - 8) {
      return declared(
          name, "GLB binary chunk length " + std::to_string(bin_length) + " exceeds the file");
    }
    bin = bin_length;
    has_bin = true;
  }
  return prescan_gltf_json(json, name, folder, bin, has_bin);
}

Status prescan_model_file(const std::filesystem::path& path, std::string_view extension) {
  const bool ply = extension == ".ply";
  const bool gltf = extension == ".gltf";
  const bool glb = extension == ".glb";
  if (!ply && !gltf && !glb) return Status::Ok();
  const std::string name = path.string();
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status(ErrorId::kFileOpen, name + ": cannot read its size: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status(ErrorId::kFileOpen, name + ": cannot open");
  std::string bytes(ply ? std::min(size, kMaxPlyHeader) : size, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<size_t>(in.gcount()) != bytes.size()) {
    return Status(ErrorId::kFileRead, name + ": read failed");
  }
  if (ply) return prescan_ply(bytes, size, name);
  const std::filesystem::path folder = path.parent_path();
  if (glb) return prescan_glb(bytes, name, folder);
  return prescan_gltf_json(bytes, name, folder, 0, false);
}

}  // namespace calf::samples::detail
