# Compiler settings applied to each of our own targets (never to dependencies).

function(ecv_target_options target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
    -Woverloaded-virtual -Wformat=2 -Wimplicit-fallthrough)
  if(ECVPOSE_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(ECVPOSE_SANITIZE)
    # -g1: line tables only, enough for the sanitizers' stack traces, and a quarter less compile time than -g.
    # UBSan without the checks at every pointer use (null, alignment, pointer-overflow, object-size): with them a
    # file takes twice as long to compile; ASan still reports a null dereference and every out-of-bounds access, and
    # the fuzzers (fuzz/) keep all of UBSan on the file readers.
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize=null,alignment,pointer-overflow,object-size
                                             -fno-sanitize-recover=undefined -g1)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

# A library of one folder: its headers are included as "<folder>/<header>.h" from the
# project root (core: from src/), and installed under include/ecvpose/ with the same names.
function(ecv_add_library target)
  cmake_parse_arguments(ARG "" "INCLUDE_ROOT" "SOURCES" ${ARGN})
  add_library(${target} ${ARG_SOURCES})
  add_library(ecvpose::${target} ALIAS ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${ARG_INCLUDE_ROOT}>
    $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/ecvpose>)
  set_target_properties(${target} PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}
                                             POSITION_INDEPENDENT_CODE ON)
  target_compile_features(${target} PUBLIC cxx_std_17)
  ecv_target_options(${target})
  set_property(GLOBAL APPEND PROPERTY ECVPOSE_LIBRARIES ${target})
endfunction()
