# `make install` (cmake --install): the core as a library for other people's code.
#   lib/libvolscissors.so            every module of src/ but io, linked whole (VTK and Boost private)
#   include/volscissors/<module>/    the modules' headers, included as "<module>/<file>.h"
#   lib/cmake/volscissors/           find_package(volscissors) -> volscissors::core
#   lib/pkgconfig/volscissors.pc     pkg-config --cflags --libs volscissors
#   bin/volscissors                  the CLI (when built)
# tests/install/install_example_test.sh builds examples/core_example against it.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The core's modules: what volscissors_core groups (so a new module is installed with no edit here).
get_target_property(vs_core_targets volscissors_core INTERFACE_LINK_LIBRARIES)
set(VS_CORE_MODULES "")
foreach(t ${vs_core_targets})
  string(REGEX REPLACE "^vs_" "" mod ${t})
  list(APPEND VS_CORE_MODULES ${mod})
endforeach()
set(vs_core_archives "")
set(vs_core_objects "")
foreach(mod ${VS_CORE_MODULES})
  get_target_property(vs_type vs_${mod} TYPE)
  if(vs_type STREQUAL "STATIC_LIBRARY")
    list(APPEND vs_core_archives vs_${mod})
    list(APPEND vs_core_objects $<TARGET_OBJECTS:vs_${mod}>)
  endif()
endforeach()

# The modules' objects (compiled once, for their archives) linked whole into one shared library;
# the archives are linked too for their packages (VTK, Boost, Threads), and then add no object.
add_library(volscissors_shared SHARED ${PROJECT_SOURCE_DIR}/cmake/core_library.cpp ${vs_core_objects})
target_compile_definitions(volscissors_shared PRIVATE VS_VERSION="${PROJECT_VERSION}")
target_link_libraries(volscissors_shared PRIVATE ${vs_core_archives})
target_link_libraries(volscissors_shared PUBLIC Threads::Threads Eigen3::Eigen nlohmann_json::nlohmann_json)
target_include_directories(volscissors_shared INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                                        $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/volscissors>)
target_compile_features(volscissors_shared PUBLIC cxx_std_20)
set_target_properties(volscissors_shared PROPERTIES OUTPUT_NAME volscissors EXPORT_NAME core
                      VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR})

install(TARGETS volscissors_shared EXPORT volscissorsTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(mod ${VS_CORE_MODULES})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/${mod}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/volscissors/${mod}
          FILES_MATCHING PATTERN "*.h")
endforeach()
install(EXPORT volscissorsTargets NAMESPACE volscissors:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/volscissors)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/volscissorsConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/volscissorsConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/volscissors)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/volscissorsConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/volscissorsConfig.cmake ${CMAKE_BINARY_DIR}/volscissorsConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/volscissors)
# The .pc file finds its prefix from its own folder, so the tree can be moved (or installed with --prefix).
file(RELATIVE_PATH VS_PC_PREFIX_FROM_PCDIR /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
configure_file(${PROJECT_SOURCE_DIR}/cmake/volscissors.pc.in ${CMAKE_BINARY_DIR}/volscissors.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/volscissors.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(TARGET volscissors)
  install(TARGETS volscissors RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
