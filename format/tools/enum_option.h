// An option whose value is one of a few names, each standing for a value of an enum: the names,
// their values, the check of a given name (CLI11's IsMember, so an unknown name is a usage error
// that lists them) and the default shown by --help all come from one table per enum, and the
// default is the value the options struct holds (header-only; commands include it).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace calf::tools {

template <typename T>
struct EnumName {
  const char* name;
  T value;
};

template <typename T, size_t N>
using EnumTable = std::array<EnumName<T>, N>;

// The name of `value` in `table` ("" when it has none).
template <typename T, size_t N>
const char* enum_name(const EnumTable<T, N>& table, T value) {
  for (const EnumName<T>& e : table) {
    if (e.value == value) return e.name;
  }
  return "";
}

// Adds the option `name` to `app`: it takes one of `table`'s names and stores its value in
// `value`, whose value now is the default --help shows. `table` must outlive the parse (a
// constant of namespace scope).
template <typename T, size_t N>
CLI::Option* add_enum_option(CLI::App& app, const std::string& name, T& value,
                             const EnumTable<T, N>& table, const std::string& help) {
  std::vector<std::string> names;
  for (const EnumName<T>& e : table) names.emplace_back(e.name);
  return app
      .add_option_function<std::string>(
          name,
          [&value, &table](const std::string& given) {
            for (const EnumName<T>& e : table) {
              if (given == e.name) value = e.value;
            }
          },
          help)
      ->check(CLI::IsMember(names))
      ->default_str(enum_name(table, value));
}

}  // namespace calf::tools
