# The test-only kind's files in each layer's library (CMake option CALF_TEST_KIND): its layout
# headers with format's, its decoder table entry in calf_decoder, its representation and player
# table entry in calf_player. A shipped kind's files sit in the layers' own folders instead.
target_include_directories(calf_format PUBLIC ${CMAKE_CURRENT_LIST_DIR}/include)
target_sources(calf_decoder PRIVATE ${CMAKE_CURRENT_LIST_DIR}/decoder/swatch_kind.cc)
target_sources(calf_player PRIVATE ${CMAKE_CURRENT_LIST_DIR}/player/swatch_kind.cc)
