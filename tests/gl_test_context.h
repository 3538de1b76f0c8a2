// The OSMesa GL 4.5 core context of a test program that draws (one per process: contexts are
// expensive under llvmpipe), and the guard that skips a GL test where the machine cannot make one.
#pragma once

#include <cstdio>
#include <memory>

#include "calf/player/gl_context.h"

namespace calf::test {

// The process's context, made current on the first call; nullptr (and a line saying why, printed
// once) when OSMesa cannot make one.
inline player::OsMesaContext* gl_context() {
  static std::unique_ptr<player::OsMesaContext> ctx = [] {
    Expected<std::unique_ptr<player::OsMesaContext>> c = player::OsMesaContext::make();
    if (!c.ok()) std::printf("no GL: %s\n", c.status().to_string().c_str());
    return c.ok() ? std::move(*c) : nullptr;
  }();
  return ctx.get();
}

}  // namespace calf::test

// First statement of a test that needs GL: skips it when there is no context.
#define CALF_REQUIRE_GL() \
  if (::calf::test::gl_context() == nullptr) GTEST_SKIP() << "no OSMesa GL 4.5 core context"
