// What Debian 12's emscripten (3.1.6: its libc++ predates C++20's std::bit_cast and floating-point
// std::to_chars) lacks of the C++20 library calf's sources use; force-included by
// web/tools/wasm_bench.mjs's emcc command, for that measurement only. The to_chars stand-ins
// (printf with enough digits to read back) only spell numbers in error messages.
#pragma once
#include <bit>
#include <charconv>
#include <cstdio>
#include <type_traits>
#if !defined(__cpp_lib_bit_cast)
namespace std {
template <class To, class From>
constexpr To bit_cast(const From& from) noexcept {
  return __builtin_bit_cast(To, from);
}
inline to_chars_result to_chars(char* first, char* last, double v) {
  const int n = snprintf(first, static_cast<size_t>(last - first), "%.17g", v);
  return {first + (n < 0 ? 0 : n < last - first ? n : last - first), errc{}};
}
inline to_chars_result to_chars(char* first, char* last, float v) {
  const int n = snprintf(first, static_cast<size_t>(last - first), "%.9g", static_cast<double>(v));
  return {first + (n < 0 ? 0 : n < last - first ? n : last - first), errc{}};
}
}  // namespace std
#endif
