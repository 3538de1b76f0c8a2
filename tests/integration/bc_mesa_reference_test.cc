// calf's CPU block decoders against Mesa's reference decoders (src/util/format, used by the
// softpipe driver): every format must agree bit for bit on every texel, signed RGTC included.
#define CALF_GALLIUM_DRIVER "softpipe"
namespace calf::bc {
enum class Format : unsigned char;
constexpr int kTolerance(Format) {
  return 0;
}
}  // namespace calf::bc
#include "bc_mesa_common.h"
