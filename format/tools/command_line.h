// What every calf command does with its command line and its errors (header-only; each command
// includes it). One rule for all of them:
//   exit 0  success, and after --help or --version (printed on stdout);
//   exit 1  an error: one line on stderr, "<command>: CALF-Ennn <message>";
//   exit 2  a usage error (unknown option, missing argument, a value of the wrong type or outside
//           its range): one line on stderr, "<command>: CALF-E006 <message> (see --help)"; a
//           range or contradiction a command checks after parsing keeps its own id (calf-capture
//           E177, calf-play E461) with exit 2.
// parse_command_line() also installs the signal handlers that remove the command's temporary
// files on SIGINT / SIGTERM / SIGHUP (calf/format/files.h). Every main runs its body through
// run_command(), so that an allocation that fails is one line too (CALF-E013, exit 1).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

#include "calf/format/files.h"
#include "calf/format/status.h"
#include "calf/format/version.h"

namespace calf::tools {

inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;
inline constexpr int kExitUsage = 2;

// The sentence each command's --help ends with.
inline constexpr const char* kExitStatusHelp =
    "Exit status: 0 success; 1 an error, printed as one line '<command>: CALF-Ennn ...' "
    "(docs/ERRORS.md); 2 a usage error (bad option or argument, options that contradict each "
    "other), one line with CALF-E006 or the option's own id.";

// The most threads a --threads option accepts (0 = all cores).
inline constexpr unsigned kMaxThreads = 256;

// Prints `status` as the command's one line on stderr (its first line only, newlines in the
// message never make a second one) and returns `exit_status`.
inline int print_error(const char* command, const Status& status, int exit_status = kExitError) {
  std::string line = status.to_string();
  const size_t newline = line.find('\n');
  if (newline != std::string::npos) line = line.substr(0, newline) + " (see --help)";
  std::fprintf(stderr, "%s: %s\n", command, line.c_str());
  return exit_status;
}

// A usage error found after parsing (options that contradict each other): CALF-E006, exit 2.
inline int usage_error(const char* command, const std::string& message) {
  return print_error(command, Status(ErrorId::kUsage, message + " (see --help)"), kExitUsage);
}

// The first value given to a floating-point option of `app` or of its parsed subcommands that is
// not a finite number ("nan", "inf", "-infinity", ...), as "--option: value ..."; empty if none.
// CLI11 reads such text as a double, and its range checks (CLI::Range, CLI::NonNegativeNumber)
// let NaN through, as every comparison with NaN is false.
inline std::string non_finite_option_value(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    if (option->count() == 0 || option->get_type_name().rfind("FLOAT", 0) != 0) continue;
    for (const std::string& text : option->results()) {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end != text.c_str() && !std::isfinite(value)) {
        return option->get_name() + ": " + text + " is not a finite number";
      }
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) {
    std::string found = non_finite_option_value(*sub);
    if (!found.empty()) return found;
  }
  return {};
}

// Checks for floating-point options that must be finite and >= `min` (> `min` when
// `exclusive`), named as CLI11's own (NONNEGATIVE, POSITIVE) so --help reads the same. CLI11's
// CLI::NonNegativeNumber and CLI::PositiveNumber accept "inf" and, like every comparison with it,
// NaN; these reject both with a message that names the bound.
inline CLI::Validator finite_at_least(double min, bool exclusive, const std::string& name) {
  return CLI::Validator(
      [min, exclusive](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return text + " is not a number";
        if (std::isfinite(value) && (exclusive ? value > min : value >= min)) return {};
        return text + " is not a finite number " + (exclusive ? "> " : ">= ") +
               CLI::detail::to_string(min);
      },
      name);
}
inline const CLI::Validator kFiniteNonNegative = finite_at_least(0, false, "NONNEGATIVE");
inline const CLI::Validator kFinitePositive = finite_at_least(0, true, "POSITIVE");

// Parses the command line. Returns -1 when the command should go on, else the exit status to
// return at once: 0 after --help / --version, 2 after a usage error (printed as one line),
// among them a floating-point option given a value that is not a finite number.
// Every command answers --version with "calf X.Y.Z" (help2man reads it for the man pages).
inline int parse_command_line(CLI::App& app, const char* command, int argc, char** argv) {
  files::install_temp_file_cleanup();
  app.set_version_flag("--version", std::string("calf ") + kVersionString);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version: stdout, exit 0
    std::string message = e.what();
    for (char& c : message)
      if (c == '\n' || c == '\r') c = ' ';
    while (!message.empty() && message.back() == ' ') message.pop_back();
    return usage_error(command, message);
  }
  if (std::string bad = non_finite_option_value(app); !bad.empty()) {
    return usage_error(command, bad);
  }
  return -1;
}

// Runs a command's body and returns its exit status. Sizes are checked before anything is
// allocated (the image budget, calf/capture/image_budget.h; every length in a file), so memory
// runs out only when the machine has less than the inputs need: the std::bad_alloc (or a
// container's std::length_error) that then escapes the body becomes the command's one line,
// CALF-E013, and exit 1 instead of an abort. Temporary files are removed by their owners as the
// exception unwinds.
template <typename Body>
int run_command(const char* command, Body&& body) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return print_error(command, Status(ErrorId::kOutOfMemory,
                                       "out of memory: the inputs need more memory than this "
                                       "machine could give (see docs/ERRORS.md)"));
  } catch (const std::length_error& e) {
    return print_error(command,
                       Status(ErrorId::kOutOfMemory, std::string("out of memory: ") + e.what()));
  }
}

}  // namespace calf::tools
