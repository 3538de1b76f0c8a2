// The test build's own track kind, "swatch" (CMake option CALF_TEST_KIND): a track that holds one
// colour per frame and plays as that colour behind everything else. It exists to show that a kind
// enters calf through the registry and its own files only (docs/ARCHITECTURE.md, "Checklist:
// adding a track kind"). A shipped build never has it; its number is reserved for it (SPEC §11).
//
// track_kinds.h includes this header when the build defines CALF_EXTRA_TRACK_KINDS_HEADER
// (tests/test_kind/registry.cmake), and puts the list below first in CALF_TRACK_KINDS; each
// layer's kind table appends its entries.
#pragma once

#define CALF_EXTRA_TRACK_KINDS(X) X(Swatch, 65535, "swatch", "none")
