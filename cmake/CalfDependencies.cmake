# Finds every dependency in DESIGN.md. Each one that is missing is collected with the Debian
# package that provides it, and configuration stops once with a single apt-get line for all of
# them (tools/setup.sh installs the same list).
find_package(PkgConfig REQUIRED)
set(CALF_MISSING_PACKAGES "")
set(CALF_MISSING_WHAT "")

macro(calf_require found what debian_package)
  if(NOT ${found})
    list(APPEND CALF_MISSING_PACKAGES ${debian_package})
    list(APPEND CALF_MISSING_WHAT "${what} (${debian_package})")
  endif()
endmacro()

macro(calf_find_config name debian_package)
  find_package(${name} ${ARGN} CONFIG QUIET)
  calf_require(${name}_FOUND ${name} ${debian_package})
endmacro()

macro(calf_find_pkgconfig prefix module debian_package)
  pkg_check_modules(${prefix} QUIET IMPORTED_TARGET GLOBAL ${module})
  calf_require(${prefix}_FOUND ${module} ${debian_package})
endmacro()

set(THREADS_PREFER_PTHREAD_FLAG ON)
find_package(Threads REQUIRED)

# format: compression and hashes
calf_find_config(zstd libzstd-dev)
calf_find_pkgconfig(LZMA liblzma liblzma-dev)
calf_find_pkgconfig(XXHASH libxxhash libxxhash-dev)
# capture sets: OpenImageIO through pkg-config, because its CMake config wants OpenCV headers
calf_find_pkgconfig(OIIO OpenImageIO libopenimageio-dev)
# PNG is decoded by libpng directly: its errors become Status values, its header is checked first
calf_find_pkgconfig(PNG libpng libpng-dev)
calf_find_config(OpenEXR libopenexr-dev)
calf_find_config(nlohmann_json nlohmann-json3-dev)
# commands
calf_find_config(CLI11 libcli11-dev)
calf_find_config(fmt libfmt-dev)
# AV1 colour (format/SPEC.md §11.1.12): SVT-AV1 encodes 4:2:0, libaom 4:4:4, dav1d decodes
calf_find_pkgconfig(SVTAV1 SvtAv1Enc libsvtav1enc-dev)
calf_find_pkgconfig(AOM aom libaom-dev)
calf_find_pkgconfig(DAV1D dav1d libdav1d-dev)
# threads for encoders and the capture tool
calf_find_config(TBB libtbb-dev)
# libsquish: its pkg-config file has an empty prefix, so find header and library directly
find_path(SQUISH_INCLUDE_DIR squish.h)
find_library(SQUISH_LIBRARY squish)
if(SQUISH_INCLUDE_DIR AND SQUISH_LIBRARY)
  set(SQUISH_FOUND TRUE)
  add_library(calf::squish UNKNOWN IMPORTED GLOBAL)
  set_target_properties(calf::squish PROPERTIES IMPORTED_LOCATION ${SQUISH_LIBRARY}
                        INTERFACE_INCLUDE_DIRECTORIES ${SQUISH_INCLUDE_DIR})
endif()
calf_require(SQUISH_FOUND libsquish libsquish-dev)
# capture: ray tracing and scene loading
calf_find_config(embree libembree-dev 3)
calf_find_config(assimp libassimp-dev)
# export: glTF writing (header-only, with nlohmann-json)
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h)
if(TINYGLTF_INCLUDE_DIR)
  set(TINYGLTF_FOUND TRUE)
  add_library(calf::tinygltf INTERFACE IMPORTED GLOBAL)
  set_target_properties(calf::tinygltf PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${TINYGLTF_INCLUDE_DIR})
endif()
calf_require(TINYGLTF_FOUND tinygltf libtinygltf-dev)
# export: EXT_meshopt_compression (vertex and index codecs)
calf_find_config(meshoptimizer libmeshoptimizer-dev)
# player
calf_find_config(glm libglm-dev)
calf_find_config(glfw3 libglfw3-dev)
set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL QUIET COMPONENTS OpenGL EGL)
calf_require(OpenGL_FOUND OpenGL "libgl-dev;libopengl-dev;libglx-dev")
calf_require(OpenGL_EGL_FOUND EGL libegl-dev)
calf_find_pkgconfig(OSMESA osmesa libosmesa6-dev)
calf_find_pkgconfig(IMGUI imgui libimgui-dev)
# Debian ships Dear ImGui without platform backends; build them from the package's own copies.
set(CALF_IMGUI_BACKENDS /usr/share/doc/libimgui-dev/examples/backends)
if(IMGUI_FOUND)
  if(EXISTS ${CALF_IMGUI_BACKENDS}/imgui_impl_glfw.cpp)
    add_library(calf_imgui_backends STATIC ${CALF_IMGUI_BACKENDS}/imgui_impl_glfw.cpp
                                           ${CALF_IMGUI_BACKENDS}/imgui_impl_opengl3.cpp)
    target_include_directories(calf_imgui_backends SYSTEM PUBLIC /usr/include/imgui/backends)
    target_link_libraries(calf_imgui_backends PUBLIC PkgConfig::IMGUI glfw OpenGL::GL)
    add_library(calf::imgui ALIAS calf_imgui_backends)
  else()
    calf_require(FALSE "imgui GLFW/OpenGL3 backend sources" libimgui-dev)
  endif()
endif()
# tests and benchmarks
calf_find_config(GTest libgtest-dev)
calf_find_config(benchmark libbenchmark-dev)

list(REMOVE_DUPLICATES CALF_MISSING_PACKAGES)
if(CALF_MISSING_PACKAGES)
  list(JOIN CALF_MISSING_WHAT "\n  " what)
  list(JOIN CALF_MISSING_PACKAGES " " pkgs)
  message(FATAL_ERROR "calf: missing dependencies:\n  ${what}\n"
                      "Install them with:  apt-get install ${pkgs}\n"
                      "(or run tools/setup.sh, which installs everything calf needs)")
endif()

# Programs used by benchmarks and demos; optional, reported but never required to build.
foreach(prog gnuplot ffmpeg xvfb-run zstd xz)
  string(TOUPPER ${prog} var)
  string(REPLACE "-" "_" var ${var})
  find_program(CALF_${var}_EXECUTABLE ${prog})
  if(NOT CALF_${var}_EXECUTABLE)
    message(STATUS "calf: optional program '${prog}' not found; benchmarks skip what needs it")
  endif()
endforeach()
