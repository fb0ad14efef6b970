# SPDX-License-Identifier: Apache-2.0
# `cmake --install` and `cpack -G DEB`: the daemons, the static libraries as namespaced targets (Impetus::world, ...),
# their headers under include/impetus/, the shipped scenes and device file, ImpetusConfig.cmake with a version file,
# and a pkg-config file. The Python package installs itself (python/CMakeLists.txt).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(IMPETUS_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/Impetus)
set(IMPETUS_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/impetus)

# Library targets, the name each has after `Impetus::`.
set(IMPETUS_EXPORTED impetus_common common impetus_mesh mesh impetus_world_manager world
    impetus_haptic_controller haptic impetus_spidar_sim device impetus_loop loop)
set(exported_targets "")
while(IMPETUS_EXPORTED)
  list(POP_FRONT IMPETUS_EXPORTED target export_name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  list(APPEND exported_targets ${target})
endwhile()
# impetus_warnings is linked privately (its flags never reach a consumer) but a static library's export names it.
install(TARGETS ${exported_targets} impetus_warnings EXPORT ImpetusTargets COMPONENT dev
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/impetus)
# The daemons carry the project's name where they are installed (PREFIX/bin/world_manager would be too generic on a
# system's PATH): impetus-world-manager, impetus-haptic-controller, impetus-spidar-sim (and viewer/: impetus-viewer).
foreach(daemon world_manager haptic_controller spidar_sim)
  impetus_install_daemon(${daemon})
endforeach()
foreach(dir common world_manager haptic_controller spidar_sim loop)
  # dds_codec.h and dds_entities.h need Cyclone's headers and the idlc-generated types, which the package does not ship.
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/impetus/${dir} COMPONENT dev
          FILES_MATCHING PATTERN "*.h" PATTERN "dds_codec.h" EXCLUDE PATTERN "dds_entities.h" EXCLUDE)
endforeach()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION ${IMPETUS_INSTALL_DATADIR}/scenes
        FILES_MATCHING PATTERN "*.json" PATTERN "*.obj" PATTERN "*.stl")  # scenes and the meshes they name
install(FILES ${PROJECT_SOURCE_DIR}/common/spidar/desktop_spidar.json
              ${PROJECT_SOURCE_DIR}/common/spidar/desktop_grip.json DESTINATION ${IMPETUS_INSTALL_DATADIR})
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/THIRD_PARTY.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

install(EXPORT ImpetusTargets NAMESPACE Impetus:: DESTINATION ${IMPETUS_INSTALL_CMAKEDIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ImpetusConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/ImpetusConfig.cmake
                              INSTALL_DESTINATION ${IMPETUS_INSTALL_CMAKEDIR}
                              PATH_VARS IMPETUS_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ImpetusConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/ImpetusConfig.cmake ${PROJECT_BINARY_DIR}/ImpetusConfigVersion.cmake
        DESTINATION ${IMPETUS_INSTALL_CMAKEDIR} COMPONENT dev)
# The way up from LIBDIR/pkgconfig to the prefix ("../.." for lib, "../../.." for lib/x86_64-linux-gnu), so the file
# names the prefix it was installed into, whatever --prefix said.
file(RELATIVE_PATH IMPETUS_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${PROJECT_SOURCE_DIR}/cmake/impetus.pc.in ${PROJECT_BINARY_DIR}/impetus.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/impetus.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT dev)

# cpack -G DEB: two packages. impetus (the runtime: daemons, viewer, Python module, scenes) depends on runtime
# libraries only; impetus-dev (headers, static libraries, CMake and pkg-config files) on it and the -dev packages a
# program built against the libraries needs.
set(CPACK_PACKAGE_NAME impetus)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME impetus)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME impetus-dev)
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "Multi-rate haptic rendering with force integration: daemons, viewer, Python module")
set(CPACK_COMPONENT_DEV_DESCRIPTION "Multi-rate haptic rendering with force integration: headers and static libraries")
set(CPACK_PACKAGE_VENDOR "Impetus")
# Whoever publishes the packages names themselves here (cmake -DIMPETUS_DEB_MAINTAINER="Name <address>"): the
# default is the project's, for builds nobody redistributes.
set(IMPETUS_DEB_MAINTAINER "Impetus developers <impetus@localhost>" CACHE STRING
    "The DEB packages' Maintainer field: Name <address>")
set(CPACK_PACKAGE_CONTACT "${IMPETUS_DEB_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Multi-rate haptic rendering with force integration")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "libode8, libbullet3.24, libddsc0debian, libassimp5, libstdc++6, libc6")
if(IMPETUS_PYTHON_DEB_DEPENDS)
  string(APPEND CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS ", ${IMPETUS_PYTHON_DEB_DEPENDS}")
endif()
string(CONCAT CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
       "impetus (= ${PROJECT_VERSION}), libode-dev, libbullet-dev, libassimp-dev, libeigen3-dev, libboost-dev, "
       "nlohmann-json3-dev, libcli11-dev")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
