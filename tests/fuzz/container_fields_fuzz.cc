// Fuzz target: the fields visitor (container_fields.h) on arbitrary bytes, through the records
// that use its float, nested-record and array paths (the lightfield view index, t chunk and
// region chunk head) and every registered track header. The first byte picks the record (and,
// for a t chunk, the second its frame count); the rest is read as that record. Whatever the
// reader accepts, the writer must accept too and reproduce exactly the bytes read, the sizer must
// count them and the printer must print them: reading, writing and sizing derive from one
// declaration, so any disagreement is a bug (std::abort).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/track_registry.h"

namespace {

using namespace calf;
using namespace calf::container;

template <class T>
void round_trip(std::span<const uint8_t> in, T t) {
  FieldReader r(in, ErrorId::kLightfieldChunk, ErrorId::kLightfieldChunk, "fuzz",
                ErrorId::kLightfieldChunk);
  if (!read_fields(t, r).ok()) return;
  std::vector<uint8_t> out;
  if (!write_fields(t, out).ok()) std::abort();
  if (out.size() != r.position() || !std::equal(out.begin(), out.end(), in.begin())) std::abort();
  FieldSizer sizer;
  T::fields(static_cast<const T&>(t), sizer);
  if (sizer.size() != out.size()) std::abort();
  (void)print_fields(t).size();
}

template <size_t... I>
void track_header(size_t index, std::span<const uint8_t> in, std::index_sequence<I...>) {
  (
      [&] {
        using H = std::variant_alternative_t<I, TrackHeader>;
        if constexpr (!std::is_same_v<H, std::monostate>) {
          if (index == I) round_trip(in, H{});
        }
      }(),
      ...);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const std::span<const uint8_t> in(data + 2, size - 2);
  const size_t kinds = std::variant_size_v<TrackHeader> - 1;
  const size_t pick = data[0] % (3 + kinds);
  switch (pick) {
    case 0:
      round_trip(in, lf::ViewIndexRecord{});
      break;
    case 1: {
      lf::CellTimeline tl;
      tl.t.resize(data[1]);  // the chunk key's frame count
      round_trip(in, std::move(tl));
      break;
    }
    case 2:
      round_trip(in, lf::RegionHead{});
      break;
    default:
      track_header(pick - 2, in, std::make_index_sequence<std::variant_size_v<TrackHeader>>{});
      break;
  }
  return 0;
}
