# cmake --install: the kanegen program, the headers and static libraries of
# the layers an ahead-of-time simulator needs (model, dynamics, engine, sim;
# not the generator), the templates and scripts kanegen reads at run time,
# the example models, and a CMake package (find_package(kanegen) gives
# kanegen::kanegen, kanegen::sim, ... and kanegen_add_model()).
include(CMakePackageConfigHelpers)

install(TARGETS kanegen EXPORT kanegenTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS kanegen_model kanegen_dynamics kanegen_engine kanegen_sim kanegen_warnings
        EXPORT kanegenTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
foreach(dir model dynamics engine sim apps/aot apps/common)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/kanegen/${dir}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()
install(FILES ${KANEGEN_TEMPLATES} DESTINATION ${CMAKE_INSTALL_DATADIR}/kanegen/templates)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/scripts/plot_work_precision.py ${PROJECT_SOURCE_DIR}/scripts/plot_simulation.py
                 ${PROJECT_SOURCE_DIR}/scripts/plot_sweep.py
        DESTINATION ${CMAKE_INSTALL_DATADIR}/kanegen/scripts)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/kanegen/models)

install(EXPORT kanegenTargets NAMESPACE kanegen:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kanegen)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/kanegenConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/kanegenConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kanegen)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/kanegenConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/kanegenConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/kanegenConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/KanegenAddModel.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kanegen)

# cpack -G DEB: a Debian package of the install above.
set(CPACK_PACKAGE_NAME kanegen)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "kanegen developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Kane's-method equations of motion for multibody spacecraft, generated as C++")
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "g++, libeigen3-dev, libfmt-dev, libyaml-cpp-dev, nlohmann-json3-dev, libcli11-dev, libsundials-dev, libspectra-dev, zlib1g-dev, libginac11")
set(CPACK_GENERATOR DEB)
include(CPack)
