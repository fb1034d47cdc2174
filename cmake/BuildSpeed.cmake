# Build speed (issue 33): ccache when it is installed, and precompiled headers.
#
# ccache: base_dir is the source tree, so that a second clone on the same
# machine (other absolute paths) hits the cache; the sloppiness ccache needs
# with precompiled headers (a .gch is always newer than the compile started);
# depend mode (the compiler's own -MD list of headers, no separate
# preprocessor run: a cold cache costs no more than a build without ccache).
option(KANEGEN_CCACHE "Compile through ccache when it is installed" ON)
if(KANEGEN_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(KANEGEN_CCACHE_PROGRAM ccache)
  if(KANEGEN_CCACHE_PROGRAM)
    set(CMAKE_CXX_COMPILER_LAUNCHER
        env "CCACHE_BASEDIR=${PROJECT_SOURCE_DIR}"
        "CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime" "CCACHE_DEPEND=1"
        ${KANEGEN_CCACHE_PROGRAM})
    message(STATUS "kanegen: compiling through ccache (${KANEGEN_CCACHE_PROGRAM})")
  endif()
endif()

# Precompiled headers: most of a translation unit's time here is spent parsing
# the standard library, Eigen and fmt; each target parses them once.
option(KANEGEN_PRECOMPILED_HEADERS "Precompile the common headers of each target" ON)
function(kanegen_precompile target)
  if(KANEGEN_PRECOMPILED_HEADERS)
    target_precompile_headers(${target} PRIVATE
      <algorithm> <array> <cmath> <functional> <map> <memory> <optional> <stdexcept> <string> <vector>
      <filesystem> <Eigen/Dense> <fmt/format.h> ${ARGN})
  endif()
endfunction()

# Unity builds: a target's sources compiled a few per translation unit, so the
# headers each file includes (GiNaC, Eigen, yaml-cpp, CLI11) are parsed and
# their templates instantiated once per batch, not once per file (a cold
# build of the CLI alone, no ccache, 2 cores: 3 min 42 s against 5 min 40 s
# file by file, measured 2026-12-04). The tests too, six files per batch:
# most of a test file's time is Eigen's and Catch2's templates instantiated
# again in every file (the test target cold, no ccache, 2 cores: 105 s wall
# and 186 CPU-s against 198 s and 325 CPU-s file by file, measured back to
# back in one clone 2026-12-06). A developer editing one file recompiles its
# batch; -DKANEGEN_UNITY_BUILD=OFF compiles file by file.
#   kanegen_unity(target [BATCH_SIZE n] [EXCLUDE source...])
# EXCLUDE: sources compiled on their own (their own compile definitions, or
# a file that must not share its unit).
#
# The batches are written here, not by CMake's UNITY_BUILD: CMake's batch
# files #include each source by its absolute path, so a second clone's
# batches differ in text and never hit ccache (measured 2026-12-05: 0 of 15
# hits). These include each source by its path relative to the batch file,
# the same text in every clone under the same layout (build/ in the tree).
#
# A unity target gets no precompiled header: with a handful of batches per
# target, building each target's .gch costs more than it saves (the CLI alone,
# cold, no ccache, 2 cores, Ninja: 201 s and 384 CPU-s without them against
# 240 s and 467 CPU-s with them, measured 2026-12-05).
option(KANEGEN_UNITY_BUILD "Compile the libraries, the CLI and the tests as unity batches" ON)
set(KANEGEN_UNITY_BATCH_SIZE 8)
function(kanegen_unity target)
  if(NOT KANEGEN_UNITY_BUILD)
    return()
  endif()
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "BATCH_SIZE" "EXCLUDE")
  if(NOT arg_BATCH_SIZE)
    set(arg_BATCH_SIZE ${KANEGEN_UNITY_BATCH_SIZE})
  endif()
  get_target_property(sources ${target} SOURCES)
  get_target_property(source_dir ${target} SOURCE_DIR)
  set(unity_dir "${CMAKE_CURRENT_BINARY_DIR}/unity")
  set(batch_files "")
  set(text "")
  set(count 0)
  set(index 0)
  set(members "")
  foreach(source IN LISTS sources)
    if(NOT source MATCHES "\\.(cpp|cc|cxx)$" OR source IN_LIST arg_EXCLUDE)
      continue()
    endif()
    get_filename_component(path "${source}" ABSOLUTE BASE_DIR "${source_dir}")
    file(RELATIVE_PATH rel "${unity_dir}" "${path}")
    string(APPEND text "#include \"${rel}\"\n")
    list(APPEND members "${path}")
    math(EXPR count "${count} + 1")
    if(count EQUAL arg_BATCH_SIZE)
      set(file "${unity_dir}/${target}_${index}.cpp")
      file(CONFIGURE OUTPUT "${file}" CONTENT "// kanegen_unity (cmake/BuildSpeed.cmake)\n${text}")
      list(APPEND batch_files "${file}")
      math(EXPR index "${index} + 1")
      set(text "")
      set(count 0)
    endif()
  endforeach()
  if(count GREATER 0)
    set(file "${unity_dir}/${target}_${index}.cpp")
    file(CONFIGURE OUTPUT "${file}" CONTENT "// kanegen_unity (cmake/BuildSpeed.cmake)\n${text}")
    list(APPEND batch_files "${file}")
  endif()
  # the sources stay listed (IDEs, dependencies) but are compiled through their batch
  set_source_files_properties(${members} PROPERTIES HEADER_FILE_ONLY ON)
  target_sources(${target} PRIVATE ${batch_files})
  set_target_properties(${target} PROPERTIES PRECOMPILE_HEADERS "")
endfunction()
