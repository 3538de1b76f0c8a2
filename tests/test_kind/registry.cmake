# The test-only kind's registry line and layout header (CMake option CALF_TEST_KIND), for every
# target: track_kinds.h includes CALF_EXTRA_TRACK_KINDS_HEADER, track_registry.h
# CALF_EXTRA_TRACK_LAYOUT; tests/CMakeLists.txt reads the kind's name from
# CALF_EXTRA_TRACK_KINDS_FILE for the conformance runner. Included before the layers are made.
set(CALF_EXTRA_TRACK_KINDS_FILE ${CMAKE_CURRENT_LIST_DIR}/include/calf/format/swatch_kind.h)
add_compile_definitions(CALF_EXTRA_TRACK_KINDS_HEADER="calf/format/swatch_kind.h"
                        CALF_EXTRA_TRACK_LAYOUT="calf/format/swatch_layout.h")
