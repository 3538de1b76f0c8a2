# A glTF written by calf-export read by a second, independent reader (Khronos' glTF-Validator,
# tests/export/gltf_validate.js): the file must have no error, no warning and no extension
# declared in extensionsUsed that it does not use, and the validator's triangle and vertex counts
# must equal the counts calf-export printed. Run as
#   cmake -DEXPORT=<calf-export> -DCLIP=<.calf> -DOUT=<.glb|.gltf> -DNODE=<node>
#         -DSCRIPT=<gltf_validate.js> -DVALIDATOR=<build/npm/node_modules/gltf-validator>
#         [-DOPTION=<a calf-export option, e.g. --meshopt>] -P CalfGltfCheck.cmake
if(NOT NODE OR NOT EXISTS "${VALIDATOR}/package.json")
  message(FATAL_ERROR "node or the glTF-Validator is missing (node '${NODE}', '${VALIDATOR}'): "
                      "tools/setup.sh installs both")
endif()
execute_process(COMMAND ${EXPORT} ${CLIP} -o ${OUT} ${OPTION} RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "calf-export failed (${rc}): ${out}${err}")
endif()
if(NOT out MATCHES " ([0-9]+) triangles")
  message(FATAL_ERROR "calf-export printed no triangle count: ${out}")
endif()
set(exported ${CMAKE_MATCH_1})
if(NOT out MATCHES " ([0-9]+) vertices")
  message(FATAL_ERROR "calf-export printed no vertex count: ${out}")
endif()
set(exported_vertices ${CMAKE_MATCH_1})
execute_process(COMMAND ${NODE} ${SCRIPT} ${OUT} ${VALIDATOR} RESULT_VARIABLE rc
                OUTPUT_VARIABLE report ERROR_VARIABLE err)
message(STATUS "calf-export: ${out}glTF-Validator: ${report}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the glTF-Validator refused ${OUT} (${rc}): ${report}${err}")
endif()
if(NOT report MATCHES "triangles ([0-9]+)")
  message(FATAL_ERROR "the validator printed no triangle count: ${report}")
endif()
if(NOT CMAKE_MATCH_1 EQUAL exported)
  message(FATAL_ERROR "the validator counts ${CMAKE_MATCH_1} triangles, calf-export wrote ${exported}")
endif()
if(NOT report MATCHES "warnings 0 ")
  message(FATAL_ERROR "the glTF-Validator warns about ${OUT}: ${report}")
endif()
if(NOT report MATCHES "unused-extensions 0")
  message(FATAL_ERROR "${OUT} declares extensions it does not use: ${report}")
endif()
if(NOT report MATCHES "vertices ([0-9]+)" OR NOT CMAKE_MATCH_1 EQUAL exported_vertices)
  message(FATAL_ERROR "the validator counts ${CMAKE_MATCH_1} vertices, calf-export printed "
                      "${exported_vertices}: ${report}")
endif()
