# Target helpers shared by every layer: compile options, layers, commands, tests, fuzz targets.

set(CALF_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wimplicit-fallthrough -Wvla)
if(CALF_WERROR)
  list(APPEND CALF_WARNINGS -Werror)
endif()

# Options every calf target compiles with.
add_library(calf_options INTERFACE)
target_compile_options(calf_options INTERFACE ${CALF_WARNINGS})
if(CALF_SANITIZE)
  target_compile_options(calf_options INTERFACE -fsanitize=address,undefined
                         -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  target_link_options(calf_options INTERFACE -fsanitize=address,undefined)
endif()

# Options of a GoogleTest file (calf_add_test), in place of calf_options. A test's own file is a
# driver: the libraries it calls, where the work and the bugs are, keep AddressSanitizer + UBSan
# at -O2, and every allocation (the test's too) stays under ASan's allocator. The test file keeps
# ASan (its own reads and writes are checked) but drops UBSan and compiles at -O1. Measured on
# mesh_track_test.cc back to back on the loaded 2-core machine: 128 s with ASan + UBSan at -O2,
# 26 s with ASan alone at -O1 (alone: 60 s at -O2; both at -O1: 64 s). At -O1 GCC 12 reports
# -Wstringop-overflow on std::vector::resize after a subtraction it cannot bound (a known false
# positive of its value-range analysis; the -O2 build of the same files keeps the warning).
# They are target options, not per-file ones, so that every test file and the precompiled
# <gtest/gtest.h> they share (calf_test_pch below) compile with the same flags.
add_library(calf_test_options INTERFACE)
target_compile_options(calf_test_options INTERFACE ${CALF_WARNINGS})
if(CALF_SANITIZE)
  target_compile_options(calf_test_options INTERFACE -fsanitize=address -fno-omit-frame-pointer
                         -O1 -Wno-stringop-overflow)
  target_link_options(calf_test_options INTERFACE -fsanitize=address,undefined)
endif()

# calf_cli_source(target source [NO_SANITIZE]): `source` includes CLI11 (header-only, all inline).
# Under UndefinedBehaviorSanitizer at -O2 one such file costs ~75 s of CPU to compile, ~20 s
# without it (measured on a 4-line CLI11 program: 78 s with ASan + UBSan, 39 s with ASan alone,
# 18.5 s with neither), and CI compiles some twenty of them. The command-line glue of the
# commands keeps AddressSanitizer and loses UBSan; a benchmark's own file (timings under a
# sanitizer mean nothing) is compiled without either. In the sanitized build both compile at -O1
# (idle VM: calf_info.cc with ASan 28.9 s at -O2, 15.6 s at -O1; bc_bench.cc without sanitizers
# 13.0 s -> 9.0 s). The libraries they link, where the work is, keep both sanitizers and -O2.
function(calf_cli_source target source)
  cmake_parse_arguments(C "NO_SANITIZE" "" "" ${ARGN})
  if(CALF_SANITIZE)
    if(C_NO_SANITIZE)
      set_source_files_properties(${source} TARGET_DIRECTORY ${target} PROPERTIES
                                  COMPILE_OPTIONS "-fno-sanitize=all;-O1")
    else()
      set_source_files_properties(${source} TARGET_DIRECTORY ${target} PROPERTIES
                                  COMPILE_OPTIONS "-fno-sanitize=undefined;-O1")
    endif()
  endif()
endfunction()

# With libFuzzer, every calf target carries coverage instrumentation (not only the fuzz target's
# own file), or the fuzzer runs blind through the libraries it is meant to explore.
if(CALF_LIBFUZZER)
  target_compile_options(calf_options INTERFACE -fsanitize=fuzzer-no-link)
endif()

# calf_layer(NAME DIR dir LINKS deps...): one library per layer. Sources are globbed so that work
# in different files never edits this list; CONFIGURE_DEPENDS re-globs on every build.
# Commands: every <dir>/tools/<name>.cc becomes the executable <name> with '_' turned into '-',
# linked to the layer, CLI11 and fmt, together with the command's own sources
# <dir>/tools/<name>/*.cc (code only that command uses, e.g. calf-play's window), which include
# their headers as "<name>/x.h".
function(calf_layer name)
  cmake_parse_arguments(L "" "DIR" "LINKS" ${ARGN})
  set(dir ${CMAKE_CURRENT_SOURCE_DIR}/${L_DIR})
  file(GLOB sources CONFIGURE_DEPENDS ${dir}/src/*.cc ${dir}/src/*/*.cc)
  if(sources)
    add_library(${name} STATIC ${sources})
    target_include_directories(${name} PUBLIC ${dir}/include PRIVATE ${dir}/src)
    target_link_libraries(${name} PUBLIC ${L_LINKS} PRIVATE calf_options)
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${dir}/include)
    target_link_libraries(${name} INTERFACE ${L_LINKS})
  endif()
  set_property(GLOBAL APPEND PROPERTY CALF_LAYERS ${name})
  file(GLOB tools CONFIGURE_DEPENDS ${dir}/tools/*.cc)
  foreach(tool_source ${tools})
    get_filename_component(tool ${tool_source} NAME_WE)
    string(REPLACE "_" "-" exe ${tool})
    file(GLOB tool_extra CONFIGURE_DEPENDS ${dir}/tools/${tool}/*.cc)
    add_executable(${exe} ${tool_source} ${tool_extra})
    set_property(GLOBAL APPEND PROPERTY CALF_COMMANDS ${exe}:${name})
    target_link_libraries(${exe} PRIVATE ${name} CLI11::CLI11 fmt::fmt calf_options)
    calf_cli_source(${exe} ${tool_source})
    # format/tools/command_line.h: the exit statuses and usage errors every command shares.
    target_include_directories(${exe} PRIVATE ${dir}/tools ${PROJECT_SOURCE_DIR}/format/tools)
  endforeach()
endfunction()

# calf_check_layering(layer:allowed1,allowed2 ...): fails configuration when a layer links a calf
# layer outside its allowed list (directly or through another layer), when a command (an
# executable of <dir>/tools) links a calf layer other than its own layer or one its layer may
# link, or when a layer has no rule.
function(calf_check_layering)
  get_property(layers GLOBAL PROPERTY CALF_LAYERS)
  get_property(commands GLOBAL PROPERTY CALF_COMMANDS)
  set(ruled "")
  foreach(rule ${ARGN})
    string(REPLACE ":" ";" parts "${rule}")
    list(GET parts 0 layer)
    list(APPEND ruled ${layer})
    list(LENGTH parts n)
    set(allowed "")
    if(n GREATER 1)
      list(GET parts 1 allowed_csv)
      string(REPLACE "," ";" allowed "${allowed_csv}")
    endif()
    get_target_property(type ${layer} TYPE)
    if(type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(links ${layer} INTERFACE_LINK_LIBRARIES)
    else()
      get_target_property(links ${layer} LINK_LIBRARIES)
    endif()
    foreach(dep ${links})
      if(dep IN_LIST layers AND NOT dep IN_LIST allowed)
        message(FATAL_ERROR "calf layering: ${layer} links ${dep}, allowed: ${allowed}")
      endif()
    endforeach()
    # The layer's commands: the layer itself and what it may link.
    foreach(entry ${commands})
      string(REPLACE ":" ";" command_parts "${entry}")
      list(GET command_parts 0 command)
      list(GET command_parts 1 command_layer)
      if(NOT command_layer STREQUAL layer)
        continue()
      endif()
      get_target_property(command_links ${command} LINK_LIBRARIES)
      foreach(dep ${command_links})
        if(dep IN_LIST layers AND NOT dep STREQUAL layer AND NOT dep IN_LIST allowed)
          message(FATAL_ERROR "calf layering: command ${command} of ${layer} links ${dep}, "
                              "allowed: ${layer} ${allowed}")
        endif()
      endforeach()
    endforeach()
  endforeach()
  foreach(layer ${layers})
    if(NOT layer IN_LIST ruled)
      message(FATAL_ERROR "calf layering: ${layer} has no rule in calf_check_layering()")
    endif()
  endforeach()
endfunction()

# calf_add_test(source [TEST_PREFIX prefix] LIBS...): one GoogleTest executable per test file,
# named after the file, and one ctest entry of the same name running all of its cases (select
# cases with `tests/<name> --gtest_filter=...`). With -DCALF_TEST_PER_CASE=ON every case is its
# own ctest entry instead, its name preceded by `prefix` when given (e.g. "extreme.").
include(GoogleTest)
add_library(calf_test_pch OBJECT ${PROJECT_SOURCE_DIR}/tests/gtest_pch.cc)
target_link_libraries(calf_test_pch PRIVATE GTest::gtest calf_test_options)
target_precompile_headers(calf_test_pch PRIVATE <gtest/gtest.h>)
function(calf_add_test source)
  cmake_parse_arguments(T "" "TEST_PREFIX" "" ${ARGN})
  get_filename_component(name ${source} NAME_WE)
  add_executable(${name} ${source})
  target_link_libraries(${name} PRIVATE ${T_UNPARSED_ARGUMENTS} GTest::gtest GTest::gtest_main
                        calf_test_options)
  # <gtest/gtest.h> is parsed once for all test files (sanitized, idle VM: view_set_test.cc
  # 2.6 s -> 1.8 s; the 89 test files' compile time summed over a -j2 build 734 s -> 699 s).
  target_precompile_headers(${name} REUSE_FROM calf_test_pch)
  # CALF_TEST_COST_<name> (tests/CMakeLists.txt): ctest starts costlier tests first when it has no
  # timings of its own yet (a fresh CI machine), so the longest ones do not end the run alone.
  set(cost 0)
  if(DEFINED CALF_TEST_COST_${name})
    set(cost ${CALF_TEST_COST_${name}})
  endif()
  if(CALF_TEST_PER_CASE)
    set(prefix "")
    if(T_TEST_PREFIX)
      set(prefix TEST_PREFIX ${T_TEST_PREFIX})
    endif()
    gtest_discover_tests(${name} DISCOVERY_MODE PRE_TEST ${prefix}
                         PROPERTIES ENVIRONMENT "CALF_SOURCE_DIR=${PROJECT_SOURCE_DIR}" COST ${cost})
  else()
    # One ctest entry runs the whole file: its cases in one process (the test output names each
    # case and every failure). A process that links the capture layer loads OpenImageIO and its
    # ~250 shared libraries, 0.3-0.8 s before main() under the sanitizers (most of it the dynamic
    # loader's symbol look-ups); one process per case spent more time starting than testing
    # (sanitized, 2-core VM, -j2: the 754 cases as 754 processes 980 s of test time, the 89
    # files as 89 processes 297 s). CALF_TEST_PER_CASE=ON restores one entry per case.
    add_test(NAME ${name} COMMAND ${name} --gtest_also_run_disabled_tests
             WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
    set_tests_properties(${name} PROPERTIES
                         ENVIRONMENT "CALF_SOURCE_DIR=${PROJECT_SOURCE_DIR}" COST ${cost})
  endif()
endfunction()

# calf_add_fuzz_target(source LIBS...): a source defining LLVMFuzzerTestOneInput. With
# CALF_LIBFUZZER (clang) it builds a libFuzzer binary; otherwise it links the standalone driver,
# which replays tests/fuzz/corpus/<name>/ and then CALF_FUZZ_ITERATIONS deterministic mutations of
# it, and registers that run as the ctest 'fuzz.<name>'.
function(calf_add_fuzz_target source)
  get_filename_component(name ${source} NAME_WE)
  add_executable(${name} ${source})
  target_link_libraries(${name} PRIVATE ${ARGN} calf_options)
  set(corpus ${PROJECT_SOURCE_DIR}/tests/fuzz/corpus/${name})
  if(CALF_LIBFUZZER)
    target_compile_options(${name} PRIVATE -fsanitize=fuzzer)
    target_link_options(${name} PRIVATE -fsanitize=fuzzer)
    add_test(NAME fuzz.${name} COMMAND ${name} -runs=${CALF_FUZZ_ITERATIONS} ${corpus})
  else()
    target_sources(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/fuzz/standalone_driver.cc)
    add_test(NAME fuzz.${name} COMMAND ${name} --iterations ${CALF_FUZZ_ITERATIONS} ${corpus})
  endif()
endfunction()
