# The test-only kind's tests (CMake option CALF_TEST_KIND; included by tests/CMakeLists.txt after
# its conformance runner, which already runs tests/conformance/swatch/ through calf-verify
# --decode): its tables' entries in process, and calf-info's and calf-verify's lines for it.
calf_add_test(${CMAKE_CURRENT_LIST_DIR}/swatch_kind_test.cc calf_decoder calf_player)
set(swatch_clip ${PROJECT_SOURCE_DIR}/tests/conformance/swatch/three_frames.calf)
calf_add_cli_test(calf_info_swatch ok "track 0: swatch.*swatch: 3 colour chunks"
  COMMAND $<TARGET_FILE:calf-info> ${swatch_clip})
calf_add_cli_test(calf_info_json_swatch ok "\"swatch\":{\"colour_chunks\":3}"
  COMMAND $<TARGET_FILE:calf-info> --json ${swatch_clip})
calf_add_cli_test(calf_verify_swatch ok ", 3 swatch frames decoded"
  COMMAND $<TARGET_FILE:calf-verify> ${swatch_clip})
