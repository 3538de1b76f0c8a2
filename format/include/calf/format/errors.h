// calf error ids: the one list of every error a calf library can return.
//
// Each id is stable: once released, a number keeps its meaning forever, so that users, scripts
// and tests can grep for "CALF-E012". A new error takes a new number in its layer's range; a
// retired one stays in the list, marked retired. docs/ERRORS.md documents every id; the test
// tests/format/errors_test.cc fails when an id here is missing from that document.
//
// Ranges:   1- 19 general (arguments, files)      20- 39 conventions (cube, log depth, grids)
//          40- 99 container (format/SPEC.md)     100-129 BCn block codecs
//         130-169 capture sets (format/CAPTURE.md) 170-199 calf-capture and sample scenes
//         200-299 encoder    300-399 decoder    400-499 player
#pragma once

#include <cstdint>

namespace calf {

// What the caller can do about an error; derived from the id, never stored separately.
enum class ErrorKind : uint8_t {
  kInvalidArgument,  // the caller passed a value the API does not accept
  kCorrupt,          // bytes in a file are wrong: a checksum, a field, a length
  kNeedMoreData,     // the input ended early: a truncated file or stream
  kUnsupported,      // valid, but uses something this build does not implement
  kLimit,            // a size or count exceeds a documented limit
  kIo,               // the operating system refused: open, read, write, rename
  kInternal,         // an invariant of calf itself failed; a bug to report
};

// X(name, number, kind, one-line summary). The summary is the headline in docs/ERRORS.md; the
// message of each Status says which file, field or value is at fault.
#define CALF_ERROR_LIST(X)                                                                      \
  /* general */                                                                                 \
  X(kInvalidArgument, 1, kInvalidArgument, "an argument is outside what the API accepts")       \
  X(kFileOpen, 2, kIo, "a file could not be opened")                                            \
  X(kFileRead, 3, kIo, "a file could not be read")                                              \
  X(kFileWrite, 4, kIo, "a file could not be written or renamed into place")                    \
  X(kInternal, 5, kInternal, "an internal invariant failed")                                    \
  /* conventions */                                                                             \
  X(kDepthRange, 20, kInvalidArgument, "z_near / z_far do not form a valid log-depth range")    \
  X(kDepthValue, 21, kCorrupt, "a depth value is NaN, negative, zero or -inf")                  \
  X(kDepthOutOfRange, 22, kInvalidArgument, "a finite depth lies outside [z_near, z_far]")      \
  X(kGridSize, 23, kInvalidArgument, "a face, cell or tile size is zero or too large")          \
  X(kGridIndex, 24, kInvalidArgument, "a cell, tile or quadtree index is outside its grid")     \
  /* container: 40-99 */                                                                        \
  /* block codecs: 100-129 */                                                                   \
  /* capture sets: 130-169 */                                                                   \
  /* calf-capture: 170-199 */                                                                   \
  /* encoder: 200-299 */                                                                        \
  /* decoder: 300-399 */                                                                        \
  /* player: 400-499 */

enum class ErrorId : uint16_t {
  kOk = 0,
#define CALF_ERROR_ENUM(name, number, kind, summary) name = number,
  CALF_ERROR_LIST(CALF_ERROR_ENUM)
#undef CALF_ERROR_ENUM
};

// The kind an id belongs to (kInternal for an id not in the list).
ErrorKind error_kind(ErrorId id);
// The one-line summary of an id ("" for kOk or an unknown id).
const char* error_summary(ErrorId id);

}  // namespace calf
