# kanegen_add_model(<target> <model.yaml> [CONTROLLER control.cpp] [SOURCES extra.cpp ...] [NO_MAIN])
#
# Builds an ahead-of-time simulator: at build time `kanegen generate` writes
# the model's header, C entry file and manifest to
# ${CMAKE_CURRENT_BINARY_DIR}/kanegen_models/<target>/ (again whenever the
# model, its modal files -- through a depfile --, or kanegen change), and the
# executable <target> compiles the entry file (which #includes the header)
# with the default main of apps/aot/aot_simulator.hpp:
#   <target> [--t-end T] [--dt-out H] [--integrator NAME] [--rtol R] [--atol A]
#            [--state S.json] [--model M.yaml] [--eval] -o OUT.csv
# The model file's absolute path is embedded; it is read at start (names,
# initial state) and must hash to the code compiled in.
#   <target> sweep SWEEP.yaml [-o DIR] [--threads N] [--run K] [--shard i/N] [--merge DIR ...]
# runs a Monte Carlo sweep of the model on the compiled-in code, closed loop
# with the compiled-in controller (docs/sweeps.md; under mpirun when Open MPI
# is found at configure time).
# CONTROLLER adds a control law to the simulator (docs/gnc.md): the file
# defines `kanegen::Controller kanegen_controller(const kanegen::Model&)`
# (sim/controller.hpp), called once at start; its law sets the model's named
# inputs from the time, state and named outputs, continuously or as a digital
# controller at a fixed rate (--open-loop runs without it). NO_MAIN leaves main()
# to SOURCES (call kanegen::aot_simulator_main() or use the header's functions
# directly). The simulator links kanegen::sim only: no GiNaC, no generator.
# Works in kanegen's own build and, after find_package(kanegen), in any project.

function(kanegen_add_model target model)
  cmake_parse_arguments(PARSE_ARGV 2 ARG "NO_MAIN" "CONTROLLER" "SOURCES")
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
    OUTPUT "${_out}/model.hpp" "${_out}/entry.cpp" "${_out}/manifest.json"
    COMMAND kanegen::kanegen generate "${_model}" -o "${_out}/model.hpp" --entry "${_out}/entry.cpp"
            --manifest "${_out}/manifest.json" --depfile "${_out}/model.d"
    DEPENDS kanegen::kanegen "${_model}"
    DEPFILE "${_out}/model.d"
    COMMENT "kanegen: generating the equations of motion of ${model} for ${target}"
    VERBATIM)
  if(NOT TARGET CLI11::CLI11)
    find_package(CLI11 REQUIRED)
  endif()
  set(_controller)
  if(ARG_CONTROLLER)
    get_filename_component(_controller "${ARG_CONTROLLER}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    if(NOT EXISTS "${_controller}")
      message(FATAL_ERROR "kanegen_add_model(${target}): controller file ${_controller} does not exist")
    endif()
  endif()
  add_executable(${target} "${_out}/entry.cpp" ${_controller} ${ARG_SOURCES})
  if(_controller)
    target_compile_definitions(${target} PRIVATE KANEGEN_HAS_CONTROLLER)
  endif()
  target_include_directories(${target} PRIVATE "${_out}")
  # kanegen's headers are C++20 (clang 14 defaults to C++14, g++ 12 to C++17)
  target_compile_features(${target} PRIVATE cxx_std_20)
  target_link_libraries(${target} PRIVATE kanegen::sim CLI11::CLI11)
  if(NOT DEFINED MPI_CXX_FOUND)
    find_package(MPI COMPONENTS CXX QUIET)
  endif()
  if(MPI_CXX_FOUND)  # <target> sweep under mpirun
    target_link_libraries(${target} PRIVATE MPI::MPI_CXX)
    target_compile_definitions(${target} PRIVATE KANEGEN_HAVE_MPI)
  endif()
  if(NOT ARG_NO_MAIN)
    target_compile_definitions(${target} PRIVATE KANEGEN_AOT_MAIN "KANEGEN_MODEL_PATH=\"${_model}\""
                                                 "KANEGEN_TARGET=\"${target}\"")
  endif()
endfunction()
