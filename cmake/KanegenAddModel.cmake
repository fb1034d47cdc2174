# kanegen_add_model(<target> <model.yaml> [SOURCES extra.cpp ...] [NO_MAIN])
#
# Builds an ahead-of-time simulator: at build time `kanegen generate` writes
# the model's header to ${CMAKE_CURRENT_BINARY_DIR}/kanegen_models/<target>/
# model.hpp, templates/entry.cpp.in wraps it into the KanegenGeneratedApi table
# (entry.cpp, namespace read from the header), and the executable <target>
# links it with kanegen_runtime and a default main (templates/aot_main.cpp.in):
#   <target> [--t-end T] [--dt-out H] [--integrator NAME] [--rtol R] [--atol A]
#            [--state S.json] [--model M.yaml] [--eval] -o OUT.csv
# The model file's absolute path is embedded; it is read at start (names,
# initial state) and must hash to the code compiled in. NO_MAIN leaves main()
# to SOURCES (call kanegen_generated_api() / kanegen::aot_simulator_main).
# Modal data files named by the model are not tracked as dependencies: a
# stale build is refused at run time by the hash check.
#
# Run in script mode (cmake -P this file) with KANEGEN_CONFIGURE_ENTRY=ON it
# configures entry.cpp from a generated header (used by the build step).

if(CMAKE_SCRIPT_MODE_FILE AND KANEGEN_CONFIGURE_ENTRY)
  file(STRINGS "${KANEGEN_HEADER}" _ns_line REGEX "^namespace kanegen_gen::[A-Za-z0-9_]+" LIMIT_COUNT 1)
  string(REGEX MATCH "kanegen_gen::[A-Za-z0-9_]+" NAMESPACE "${_ns_line}")
  if(NOT NAMESPACE)
    message(FATAL_ERROR "kanegen: no 'namespace kanegen_gen::<model>' in ${KANEGEN_HEADER}")
  endif()
  set(HEADER "${KANEGEN_HEADER}")
  configure_file("${KANEGEN_ENTRY_TEMPLATE}" "${KANEGEN_OUTPUT}" @ONLY)
  return()
endif()

function(kanegen_add_model target model)
  cmake_parse_arguments(PARSE_ARGV 2 ARG "NO_MAIN" "" "SOURCES")
  # Located from this file (the caller may be in any directory scope).
  set(_KANEGEN_ADD_MODEL_FILE "${CMAKE_CURRENT_FUNCTION_LIST_FILE}")
  get_filename_component(_KANEGEN_ROOT "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/.." ABSOLUTE)
  set(KANEGEN_TEMPLATE_FILES
    "${_KANEGEN_ROOT}/templates/model.hpp.in"
    "${_KANEGEN_ROOT}/templates/entry.cpp.in"
    "${_KANEGEN_ROOT}/templates/aot_main.cpp.in")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "kanegen_add_model(${target}): unexpected arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  get_filename_component(_model "${model}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT EXISTS "${_model}")
    message(FATAL_ERROR "kanegen_add_model(${target}): model file ${_model} does not exist")
  endif()
  set(_out "${CMAKE_CURRENT_BINARY_DIR}/kanegen_models/${target}")
  file(MAKE_DIRECTORY "${_out}")

  add_custom_command(
    OUTPUT "${_out}/model.hpp" "${_out}/entry.cpp"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${_out}"
    COMMAND $<TARGET_FILE:kanegen> generate "${_model}" -o "${_out}/model.hpp" --depfile "${_out}/model.d"
    COMMAND "${CMAKE_COMMAND}" -DKANEGEN_CONFIGURE_ENTRY=ON "-DKANEGEN_HEADER=${_out}/model.hpp"
            "-DKANEGEN_ENTRY_TEMPLATE=${_KANEGEN_ROOT}/templates/entry.cpp.in" "-DKANEGEN_OUTPUT=${_out}/entry.cpp"
            -P "${_KANEGEN_ADD_MODEL_FILE}"
    DEPENDS kanegen "${_model}" ${KANEGEN_TEMPLATE_FILES} "${_KANEGEN_ADD_MODEL_FILE}"
    DEPFILE "${_out}/model.d"
    COMMENT "kanegen: generating the equations of motion of ${model} for ${target}"
    VERBATIM)

  set(_sources "${_out}/entry.cpp" ${ARG_SOURCES})
  if(NOT ARG_NO_MAIN)
    set(KANEGEN_MODEL_PATH "${_model}")
    set(KANEGEN_TARGET "${target}")
    configure_file("${_KANEGEN_ROOT}/templates/aot_main.cpp.in" "${_out}/aot_main.cpp" @ONLY)
    list(APPEND _sources "${_out}/aot_main.cpp")
  endif()
  if(NOT TARGET CLI11::CLI11)
    find_package(CLI11 REQUIRED)
  endif()
  add_executable(${target} ${_sources})
  target_include_directories(${target} PRIVATE "${_out}")
  target_link_libraries(${target} PRIVATE kanegen_runtime CLI11::CLI11)
endfunction()
