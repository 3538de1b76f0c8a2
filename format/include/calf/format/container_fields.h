// Field declarations for the calf container (format/SPEC.md): every on-disk structure lists its
// fields once, and reading, writing, sizing, range checking and printing are all derived from
// that one list (the libjxl `fields.h` habit: no hand-kept twin parser and writer).
//
// A structure declares its fields in a static template:
//
//   struct Example {
//     uint32_t width = 0;
//     std::string name;
//     template <class Self, class Visitor>
//     static constexpr void fields(Self& s, Visitor& v) {
//       v(s.width, "width", Range{1, 16384});   // below min: corrupt, above max: limit
//       v(s.name, "name", Range{0, 255});       // u32 byte count + bytes; max bounds the count
//     }
//   };
//
// and then: write_fields(example, bytes), FieldReader r(bytes, ...); read_fields(example, r),
// fixed_size<Example>() (compile time, for structures without strings), print_fields(example).
//
// Encoding: unsigned integers little-endian in their declared width; std::array<uint8_t, N>
// verbatim; byte strings (std::string, std::vector<uint8_t>) as a u32 byte count then the bytes.
// Nothing is aligned or padded inside a structure.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "calf/format/status.h"

namespace calf::container {

// The accepted values of a field: [min, max]. For a byte string it bounds the byte count.
struct Range {
  uint64_t min = 0;
  uint64_t max = UINT64_MAX;
};

// Concatenates its arguments with operator<< (uint8_t prints as a number): error messages
// without fmt, which the format layer may not link.
template <class... Args>
std::string cat(const Args&... args) {
  std::ostringstream os;
  auto put = [&os](const auto& a) {
    if constexpr (std::is_same_v<std::decay_t<decltype(a)>, uint8_t>) {
      os << static_cast<unsigned>(a);
    } else {
      os << a;
    }
  };
  (put(args), ...);
  return os.str();
}

// Little-endian load/store of the low `n` bytes of a value.
inline void store_le(uint8_t* p, uint64_t v, size_t n) {
  for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
inline uint64_t load_le(const uint8_t* p, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v |= static_cast<uint64_t>(p[i]) << (8 * i);
  return v;
}

template <class T>
concept UnsignedField = std::is_unsigned_v<T> && !std::is_same_v<T, bool>;
template <class T>
concept ByteString = std::is_same_v<T, std::string> || std::is_same_v<T, std::vector<uint8_t>>;

// Sizer: the encoded size of a structure. constexpr for structures of fixed size.
class FieldSizer {
 public:
  template <UnsignedField T>
  constexpr void operator()(const T&, const char*, Range = {}) {
    size_ += sizeof(T);
  }
  template <size_t N>
  constexpr void operator()(const std::array<uint8_t, N>&, const char*, Range = {}) {
    size_ += N;
  }
  template <ByteString S>
  constexpr void operator()(const S& s, const char*, Range = {}) {
    size_ += 4 + s.size();
  }
  constexpr size_t size() const { return size_; }

 private:
  size_t size_ = 0;
};

// The encoded size of a structure made only of integers and arrays, at compile time.
template <class T>
constexpr size_t fixed_size() {
  FieldSizer sizer;
  const T t{};
  T::fields(t, sizer);
  return sizer.size();
}

// Writer: appends each field to a byte vector. A value outside its Range is refused with
// kContainerWriterMisuse (the writer never produces a file its reader would reject).
class FieldWriter {
 public:
  explicit FieldWriter(std::vector<uint8_t>& out, std::string context = {})
      : out_(out), context_(std::move(context)) {}
  // Writes values outside their Range too: only for building malformed test files.
  void allow_out_of_range() { check_ranges_ = false; }
  template <UnsignedField T>
  void operator()(const T& v, const char* name, Range r = {}) {
    check(v, name, r);
    const size_t at = out_.size();
    out_.resize(at + sizeof(T));
    store_le(out_.data() + at, v, sizeof(T));
  }
  template <size_t N>
  void operator()(const std::array<uint8_t, N>& a, const char*, Range = {}) {
    out_.insert(out_.end(), a.begin(), a.end());
  }
  template <ByteString S>
  void operator()(const S& s, const char* name, Range r = {}) {
    check(s.size(), name, r);
    (*this)(static_cast<uint32_t>(s.size()), name);
    out_.insert(out_.end(), s.begin(), s.end());
  }
  const Status& status() const { return status_; }

 private:
  void check(uint64_t v, const char* name, Range r) {
    if (check_ranges_ && status_.ok() && (v < r.min || v > r.max)) {
      status_ = Status(ErrorId::kContainerWriterMisuse,
                       cat(context_, context_.empty() ? "" : ": ", name, " ", v, " is outside [",
                           r.min, ", ", r.max, "]"));
    }
  }
  std::vector<uint8_t>& out_;
  std::string context_;
  Status status_;
  bool check_ranges_ = true;
};

// Reader: reads fields from a byte span, bounds-checked. The first failure is kept and every
// later field reads as zero / empty, so a structure's fields() never needs early returns.
//  - running past the end: `short_id` (which the caller picks: a truncated directory and a short
//    track header are different errors);
//  - a value below its Range min: `short_id`'s sibling `invalid_id`; above max: kContainerLimit.
// A byte string's count is checked against its max and against the bytes left BEFORE anything
// is allocated.
class FieldReader {
 public:
  FieldReader(std::span<const uint8_t> in, ErrorId short_id, ErrorId invalid_id,
              std::string context)
      : in_(in), short_id_(short_id), invalid_id_(invalid_id), context_(std::move(context)) {}

  template <UnsignedField T>
  void operator()(T& v, const char* name, Range r = {}) {
    v = 0;
    if (!need(sizeof(T), name)) return;
    v = static_cast<T>(load_le(in_.data() + pos_, sizeof(T)));
    pos_ += sizeof(T);
    check(v, name, r);
  }
  template <size_t N>
  void operator()(std::array<uint8_t, N>& a, const char* name, Range = {}) {
    a = {};
    if (!need(N, name)) return;
    for (size_t i = 0; i < N; ++i) a[i] = in_[pos_ + i];
    pos_ += N;
  }
  template <ByteString S>
  void operator()(S& s, const char* name, Range r = {}) {
    s.clear();
    uint32_t n = 0;
    (*this)(n, name);
    check(n, name, r);
    if (!status_.ok() || !need(n, name)) return;
    s.assign(in_.begin() + static_cast<std::ptrdiff_t>(pos_),
             in_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
  }

  const Status& status() const { return status_; }
  size_t position() const { return pos_; }
  size_t remaining() const { return in_.size() - pos_; }
  // Names what the following fields belong to in error messages ("chunk 37").
  void set_context(std::string context) { context_ = std::move(context); }
  void fail(ErrorId id, const std::string& message) {
    if (status_.ok()) status_ = Status(id, prefix() + message);
  }

 private:
  std::string prefix() const { return context_.empty() ? "" : context_ + ": "; }
  bool need(uint64_t n, const char* name) {
    if (!status_.ok()) return false;
    if (n > remaining()) {
      fail(short_id_,
           cat(name, " needs ", n, " bytes at offset ", pos_, ", only ", remaining(), " left"));
      return false;
    }
    return true;
  }
  void check(uint64_t v, const char* name, Range r) {
    if (!status_.ok()) return;
    if (v < r.min) fail(invalid_id_, cat(name, " ", v, " is below its minimum ", r.min));
    if (v > r.max) fail(ErrorId::kContainerLimit, cat(name, " ", v, " exceeds its limit ", r.max));
  }

  std::span<const uint8_t> in_;
  size_t pos_ = 0;
  ErrorId short_id_, invalid_id_;
  std::string context_;
  Status status_;
};

// Printer: (name, value) pairs for calf-info; arrays and strings print as hex / text.
class FieldPrinter {
 public:
  struct Entry {
    std::string name;
    std::string value;
    bool numeric;
  };
  template <UnsignedField T>
  void operator()(const T& v, const char* name, Range = {}) {
    entries_.push_back({name, std::to_string(static_cast<uint64_t>(v)), true});
  }
  template <size_t N>
  void operator()(const std::array<uint8_t, N>& a, const char* name, Range = {}) {
    static const char* kHex = "0123456789abcdef";
    std::string hex;
    for (uint8_t b : a) hex += {kHex[b >> 4], kHex[b & 15]};
    entries_.push_back({name, hex, false});
  }
  template <ByteString S>
  void operator()(const S& s, const char* name, Range = {}) {
    entries_.push_back({name, cat(s.size(), " bytes"), false});
  }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;
};

template <class T>
Status write_fields(const T& t, std::vector<uint8_t>& out, std::string context = {}) {
  FieldWriter w(out, std::move(context));
  T::fields(t, w);
  return w.status();
}
template <class T>
Status read_fields(T& t, FieldReader& r) {
  T::fields(t, r);
  return r.status();
}
template <class T>
std::vector<FieldPrinter::Entry> print_fields(const T& t) {
  FieldPrinter p;
  T::fields(t, p);
  return p.entries();
}

}  // namespace calf::container
