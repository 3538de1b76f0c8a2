// Field declarations for calf's on-disk structures (format/SPEC.md): every structure lists its
// fields once, and reading, writing, sizing, range checking and printing are all derived from
// that one list (the libjxl `fields.h` habit: no hand-kept twin parser and writer). The container
// (container_types.h) and every track kind's chunk layout (format/<kind>_layout.h) use it.
//
// A structure declares its fields in a static template:
//
//   struct Example {
//     uint32_t width = 0;
//     float scale = 1;
//     std::string name;
//     Rect box;                          // a nested record: a struct with its own fields()
//     std::vector<uint32_t> keys;        // a counted array
//     std::vector<Rect> boxes;           // an array whose length an earlier field gives
//     template <class Self, class Visitor>
//     static constexpr void fields(Self& s, Visitor& v) {
//       v(s.width, "width", Range{1, 16384});   // below min: invalid, above max: limit
//       v(s.scale, "scale", FloatRule::kFinite);  // NaN / +-inf refused
//       v(s.name, "name", Range{0, 255});       // u32 byte count + bytes; max bounds the count
//       v(s.box, "box");                        // the record's fields, in place
//       v(s.keys, "keys", Range{1, 64});        // u32 count + elements; the Range bounds the count
//       v(s.boxes, "boxes", Length{s.width});   // `width` elements, no count on disk
//     }
//   };
//
// and then: write_fields(example, bytes), FieldReader r(bytes, ...); read_fields(example, r),
// fixed_size<Example>() (compile time, for structures without strings or vectors),
// print_fields(example).
//
// Encoding: unsigned integers little-endian in their declared width; f32 / f64 as the
// little-endian bytes of their IEEE 754 binary32 / binary64 value; std::array<uint8_t, N>
// verbatim; byte strings (std::string, std::vector<uint8_t>) as a u32 byte count then the bytes;
// fixed arrays (T[N], std::array<T, N>) as their N elements; counted arrays (std::vector<T>) as a
// u32 element count then the elements; Length arrays as their elements alone; nested records as
// their fields. Nothing is aligned or padded inside a structure.
//
// Reading trusts nothing: a count is checked against its Range and against the bytes left
// (count x the element's smallest encoding) BEFORE anything is allocated.
#pragma once

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "calf/format/status.h"

namespace calf::container {

// The accepted values of an integer field: [min, max]. For a byte string or a counted array it
// bounds the count.
struct Range {
  uint64_t min = 0;
  uint64_t max = UINT64_MAX;
};

// The accepted values of a float field. kFinite refuses NaN and +-inf: reading one is the
// reader's `invalid_id`, writing one kContainerWriterMisuse.
enum class FloatRule : uint8_t { kAny, kFinite };

// The length of an array that is not counted on disk: an earlier field (or the caller) gives it.
struct Length {
  uint64_t count = 0;
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

// The shortest text that reads back as the same float ("0.1", "1e+300", "nan", "-inf").
template <class F>
std::string float_text(F f) {
  if (std::isnan(f)) return "nan";
  if (std::isinf(f)) return f < 0 ? "-inf" : "inf";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  return std::string(buf, r.ptr);
}

namespace detail {
// A visitor that accepts anything: only used to ask whether a type declares fields().
struct AnyVisitor {
  template <class... A>
  constexpr void operator()(A&&...) {}
};
}  // namespace detail

template <class T>
concept UnsignedField = std::is_unsigned_v<T> && !std::is_same_v<T, bool>;
template <class T>
concept FloatField = std::is_same_v<T, float> || std::is_same_v<T, double>;
template <class T>
concept ByteString = std::is_same_v<T, std::string> || std::is_same_v<T, std::vector<uint8_t>>;
// A nested record: a structure with a static fields() template.
template <class T>
concept Record = requires(T& t, detail::AnyVisitor& v) {
  T::fields(t, v);
};
// What an array may hold: integers, floats, records.
template <class T>
concept Element = UnsignedField<T> || FloatField<T> || Record<T>;
// The element type of a counted array or std::array; std::vector<uint8_t> is a byte string and
// std::array<uint8_t, N> raw bytes instead (the same bytes on disk).
template <class T>
concept CountedElement = Element<T> && !std::is_same_v<T, uint8_t>;

// Where a visitor is inside nested records and arrays ("rects[3].w"), kept as pointers and
// indices in place (no allocation), so that reading pays nothing for names until a message needs
// one. Levels beyond kMaxDepth are counted but print as "...".
class FieldPath {
 public:
  static constexpr size_t kMaxDepth = 8;
  void push(const char* name, size_t index = kNoIndex) {
    if (depth_ < kMaxDepth) parts_[depth_] = {name, index};
    ++depth_;
  }
  void pop() { --depth_; }
  // The path of field `name` inside the current record.
  std::string where(const char* name) const {
    std::string out;
    const size_t n = depth_ < kMaxDepth ? depth_ : kMaxDepth;
    for (size_t i = 0; i < n; ++i) {
      const Part& p = parts_[i];
      out += p.index == kNoIndex ? cat(p.name, '.') : cat(p.name, '[', p.index, "].");
    }
    if (depth_ > kMaxDepth) out += "...";
    // An array element of integers or floats names itself by its index alone.
    if (depth_ > 0 && depth_ <= kMaxDepth && parts_[depth_ - 1].index != kNoIndex &&
        parts_[depth_ - 1].name == name) {
      out.pop_back();
      return out;
    }
    return out + name;
  }

 private:
  static constexpr size_t kNoIndex = SIZE_MAX;
  struct Part {
    const char* name = "";
    size_t index = kNoIndex;
  };
  std::array<Part, kMaxDepth> parts_{};
  size_t depth_ = 0;
};

// Sizer: the encoded size of a structure. constexpr for structures of fixed size.
class FieldSizer {
 public:
  template <UnsignedField T>
  constexpr void operator()(const T&, const char*, Range = {}) {
    size_ += sizeof(T);
  }
  template <FloatField T>
  constexpr void operator()(const T&, const char*, FloatRule = FloatRule::kAny) {
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
  template <Record T>
  constexpr void operator()(const T& t, const char*) {
    T::fields(t, *this);
  }
  template <Element T, size_t N, class... Rule>
  constexpr void operator()(const T (&a)[N], const char* name, Rule... rule) {
    for (const T& e : a) (*this)(e, name, rule...);
  }
  template <CountedElement T, size_t N, class... Rule>
  constexpr void operator()(const std::array<T, N>& a, const char* name, Rule... rule) {
    for (const T& e : a) (*this)(e, name, rule...);
  }
  template <CountedElement T, class... Rule>
  constexpr void operator()(const std::vector<T>& a, const char* name, Range = {}, Rule... rule) {
    size_ += 4;
    for (const T& e : a) (*this)(e, name, rule...);
  }
  template <Element T, class... Rule>
  constexpr void operator()(const std::vector<T>& a, const char* name, Length, Rule... rule) {
    for (const T& e : a) (*this)(e, name, rule...);
  }
  constexpr size_t size() const { return size_; }

 private:
  size_t size_ = 0;
};

// The encoded size of a structure made only of numbers, fixed arrays and records, at compile time.
template <class T>
constexpr size_t fixed_size() {
  FieldSizer sizer;
  const T t{};
  T::fields(t, sizer);
  return sizer.size();
}

// The smallest encoding of a T: its size with every string and counted array empty. A reader
// multiplies a count by it to know, before allocating, whether the elements can be there.
template <class T>
size_t min_size() {
  if constexpr (std::is_arithmetic_v<T>) {
    return sizeof(T);
  } else {
    FieldSizer sizer;
    const T t{};
    T::fields(t, sizer);
    return sizer.size();
  }
}

// What the writer, reader and printer visit alike: nested records and fixed arrays, each element
// visited in place under its path ("points[2].x"). `D` is the visitor (CRTP); constness follows
// the visited value (const for the writer and printer, mutable for the reader).
template <class D>
class CompositeFields {
 public:
  template <class T>
  requires Record<std::remove_const_t<T>>
  void operator()(T& t, const char* name) {
    path_.push(name);
    std::remove_const_t<T>::fields(t, self());
    path_.pop();
  }
  template <class T, size_t N, class... Rule>
  requires Element<std::remove_const_t<T>>
  void operator()(T (&a)[N], const char* name, Rule... rule) {
    elements(std::span<T>(a), name, rule...);
  }
  template <CountedElement T, size_t N, class... Rule>
  void operator()(const std::array<T, N>& a, const char* name, Rule... rule) {
    elements(std::span<const T>(a), name, rule...);
  }
  template <CountedElement T, size_t N, class... Rule>
  void operator()(std::array<T, N>& a, const char* name, Rule... rule) {
    elements(std::span<T>(a), name, rule...);
  }

 protected:
  // Visits each element of `a` as "name[i]"; stops at the first failure of a reader.
  template <class T, class... Rule>
  void elements(std::span<T> a, const char* name, Rule... rule) {
    for (size_t i = 0; i < a.size() && self().ok(); ++i) {
      path_.push(name, i);
      // A record element's fields are named "array[i].field", not "array[i].array.field".
      if constexpr (Record<std::remove_const_t<T>>)
        std::remove_const_t<T>::fields(a[i], self());
      else
        self()(a[i], name, rule...);
      path_.pop();
    }
  }
  FieldPath path_;

 private:
  D& self() { return static_cast<D&>(*this); }
};

// Writer: appends each field to a byte vector. A value outside its Range, a float its rule
// forbids, or a Length array of another length is refused with kContainerWriterMisuse (the
// writer never produces a file its reader would reject); the first refusal is kept.
class FieldWriter : public CompositeFields<FieldWriter> {
 public:
  using CompositeFields::operator();
  explicit FieldWriter(std::vector<uint8_t>& out, std::string context = {})
      : out_(out), context_(std::move(context)) {}
  // Writes values outside their Range too: only for building malformed test files.
  void allow_out_of_range() { check_ranges_ = false; }
  template <UnsignedField T>
  void operator()(const T& v, const char* name, Range r = {}) {
    if (check_ranges_ && (v < r.min || v > r.max))
      misuse(name, cat(" ", v, " is outside [", r.min, ", ", r.max, "]"));
    put(v, sizeof(T));
  }
  template <FloatField T>
  void operator()(const T& v, const char* name, FloatRule rule = FloatRule::kAny) {
    if (check_ranges_ && rule == FloatRule::kFinite && !std::isfinite(v))
      misuse(name, cat(" ", float_text(v), " is not finite"));
    if constexpr (sizeof(T) == 4)
      put(std::bit_cast<uint32_t>(v), 4);
    else
      put(std::bit_cast<uint64_t>(v), 8);
  }
  template <size_t N>
  void operator()(const std::array<uint8_t, N>& a, const char*, Range = {}) {
    bytes(a.data(), N);
  }
  template <ByteString S>
  void operator()(const S& s, const char* name, Range r = {}) {
    count(s.size(), name, r);
    bytes(reinterpret_cast<const uint8_t*>(s.data()), s.size());
  }
  template <CountedElement T, class... Rule>
  void operator()(const std::vector<T>& a, const char* name, Range r = {}, Rule... rule) {
    count(a.size(), name, r);
    elements(std::span<const T>(a), name, rule...);
  }
  template <Element T, class... Rule>
  void operator()(const std::vector<T>& a, const char* name, Length n, Rule... rule) {
    if (a.size() != n.count) misuse(name, cat(" holds ", a.size(), " elements, not ", n.count));
    if constexpr (std::is_same_v<T, uint8_t>)
      bytes(a.data(), a.size());
    else
      elements(std::span<const T>(a), name, rule...);
  }
  const Status& status() const { return status_; }
  bool ok() const { return status_.ok(); }

 private:
  // Appends n bytes (resize + copy: GCC 12 misreads vector::insert of a small array inlined into
  // a record's fields() as an overflow, -Wstringop-overflow).
  void bytes(const uint8_t* p, size_t n) {
    if (n == 0) return;
    const size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, p, n);
  }
  void put(uint64_t v, size_t n) {
    const size_t at = out_.size();
    out_.resize(at + n);
    store_le(out_.data() + at, v, n);
  }
  void count(uint64_t n, const char* name, Range r) {
    if (check_ranges_ && (n < r.min || n > r.max))
      misuse(name, cat(" count ", n, " is outside [", r.min, ", ", r.max, "]"));
    if (n > UINT32_MAX) misuse(name, cat(" count ", n, " does not fit a u32"));
    put(n, 4);
  }
  void misuse(const char* name, const std::string& what) {
    if (status_.ok())
      status_ = Status(ErrorId::kContainerWriterMisuse,
                       cat(context_, context_.empty() ? "" : ": ", path_.where(name), what));
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
//  - a value below its Range min, or a float its rule forbids: `invalid_id`; above its max:
//    `limit_id` (kContainerLimit unless the caller names another, as a chunk layout does whose
//    every contradiction is one corrupt-chunk error).
// A byte string's or counted array's count is checked against its max and against the bytes
// left BEFORE anything is allocated; so is a Length array's length.
class FieldReader : public CompositeFields<FieldReader> {
 public:
  using CompositeFields::operator();
  FieldReader(std::span<const uint8_t> in, ErrorId short_id, ErrorId invalid_id,
              std::string context, ErrorId limit_id = ErrorId::kContainerLimit)
      : in_(in),
        short_id_(short_id),
        invalid_id_(invalid_id),
        limit_id_(limit_id),
        context_(std::move(context)) {}

  template <UnsignedField T>
  void operator()(T& v, const char* name, Range r = {}) {
    v = 0;
    if (!need(sizeof(T), name)) return;
    v = static_cast<T>(load_le(in_.data() + pos_, sizeof(T)));
    pos_ += sizeof(T);
    check(v, name, r);
  }
  template <FloatField T>
  void operator()(T& v, const char* name, FloatRule rule = FloatRule::kAny) {
    v = 0;
    if (!need(sizeof(T), name)) return;
    if constexpr (sizeof(T) == 4)
      v = std::bit_cast<float>(static_cast<uint32_t>(load_le(in_.data() + pos_, 4)));
    else
      v = std::bit_cast<double>(load_le(in_.data() + pos_, 8));
    pos_ += sizeof(T);
    if (rule == FloatRule::kFinite && !std::isfinite(v))
      fail(invalid_id_, cat(path_.where(name), " ", float_text(v), " is not finite"));
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
    const uint32_t n = count(name, r, 1);
    if (!status_.ok()) return;
    s.assign(in_.begin() + static_cast<std::ptrdiff_t>(pos_),
             in_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
  }
  template <CountedElement T, class... Rule>
  void operator()(std::vector<T>& a, const char* name, Range r = {}, Rule... rule) {
    a.clear();
    const uint32_t n = count(name, r, min_size<T>());
    if (!status_.ok()) return;
    a.resize(n);
    elements(std::span<T>(a), name, rule...);
  }
  template <Element T, class... Rule>
  void operator()(std::vector<T>& a, const char* name, Length n, Rule... rule) {
    a.clear();
    // n.count * min_size cannot overflow for any count a caller derives from u32 fields.
    if (!need(n.count * min_size<T>(), name)) return;
    if constexpr (std::is_same_v<T, uint8_t>) {
      a.assign(in_.begin() + static_cast<std::ptrdiff_t>(pos_),
               in_.begin() + static_cast<std::ptrdiff_t>(pos_ + n.count));
      pos_ += n.count;
    } else {
      a.resize(n.count);
      elements(std::span<T>(a), name, rule...);
    }
  }

  const Status& status() const { return status_; }
  bool ok() const { return status_.ok(); }
  size_t position() const { return pos_; }
  size_t remaining() const { return in_.size() - pos_; }
  // The bytes after the last field read.
  std::span<const uint8_t> rest() const { return in_.subspan(pos_); }
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
      fail(short_id_, cat(path_.where(name), " needs ", n, " bytes at offset ", pos_, ", only ",
                          remaining(), " left"));
      return false;
    }
    return true;
  }
  void check(uint64_t v, const char* name, Range r) {
    if (!status_.ok()) return;
    if (v < r.min)
      fail(invalid_id_, cat(path_.where(name), " ", v, " is below its minimum ", r.min));
    if (v > r.max) fail(limit_id_, cat(path_.where(name), " ", v, " exceeds its limit ", r.max));
  }
  // Reads a u32 count, checks it against `r` and against the bytes left for that many elements
  // of at least `element_bytes` each.
  uint32_t count(const char* name, Range r, size_t element_bytes) {
    uint32_t n = 0;
    (*this)(n, name);
    check(n, name, r);
    if (!need(uint64_t{n} * element_bytes, name)) return 0;
    return n;
  }

  std::span<const uint8_t> in_;
  size_t pos_ = 0;
  ErrorId short_id_, invalid_id_, limit_id_;
  std::string context_;
  Status status_;
};

// Printer: (name, value) pairs for calf-info. Nested fields are named "record.field", array
// elements "array[i]"; counted arrays also print their count as "array.count"; fixed byte
// arrays print as hex, byte strings as their length. Floats print exactly (shortest form).
class FieldPrinter : public CompositeFields<FieldPrinter> {
 public:
  using CompositeFields::operator();
  struct Entry {
    std::string name;
    std::string value;
    bool numeric;  // a JSON number (not NaN or an infinity)
  };
  template <UnsignedField T>
  void operator()(const T& v, const char* name, Range = {}) {
    add(name, std::to_string(static_cast<uint64_t>(v)), true);
  }
  template <FloatField T>
  void operator()(const T& v, const char* name, FloatRule = FloatRule::kAny) {
    add(name, float_text(v), std::isfinite(v));
  }
  template <size_t N>
  void operator()(const std::array<uint8_t, N>& a, const char* name, Range = {}) {
    static const char* kHex = "0123456789abcdef";
    std::string hex;
    for (uint8_t b : a) hex += {kHex[b >> 4], kHex[b & 15]};
    add(name, hex, false);
  }
  template <ByteString S>
  void operator()(const S& s, const char* name, Range = {}) {
    add(name, cat(s.size(), " bytes"), false);
  }
  template <CountedElement T, class... Rule>
  void operator()(const std::vector<T>& a, const char* name, Range = {}, Rule... rule) {
    add((std::string(name) + ".count").c_str(), std::to_string(a.size()), true);
    elements(std::span<const T>(a), name, rule...);
  }
  template <Element T, class... Rule>
  void operator()(const std::vector<T>& a, const char* name, Length, Rule... rule) {
    if constexpr (std::is_same_v<T, uint8_t>)
      add(name, cat(a.size(), " bytes"), false);
    else
      elements(std::span<const T>(a), name, rule...);
  }
  const std::vector<Entry>& entries() const { return entries_; }
  bool ok() const { return true; }

 private:
  void add(const char* name, std::string value, bool numeric) {
    entries_.push_back({path_.where(name), std::move(value), numeric});
  }
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
