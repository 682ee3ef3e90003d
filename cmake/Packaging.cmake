# `cmake --install` with an exported package, so that find_package(ecvpose) works elsewhere.
include(CMakePackageConfigHelpers)

get_property(ecv_libraries GLOBAL PROPERTY ECVPOSE_LIBRARIES)
install(TARGETS ${ecv_libraries} ecvpose
        EXPORT ecvposeTargets
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
# The viewer, beside ecvpose, which it starts (app/view/).
install(TARGETS ecvpose-view RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The mesh importer program, in the folder where LoadMesh looks for it (io/mesh_io.cpp).
install(TARGETS ecvpose-mesh-import RUNTIME DESTINATION ${CMAKE_INSTALL_LIBDIR}/ecvpose)

# Public headers keep their folder: include/ecvpose/core/camera.h, include/ecvpose/render/...
install(DIRECTORY src/core src/ecv src/io src/registration DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ecvpose FILES_MATCHING PATTERN "*.h")
foreach(stage render colorcal modeldb recognize camera)
  install(DIRECTORY ${stage} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ecvpose FILES_MATCHING PATTERN "*.h")
endforeach()
install(FILES "${PROJECT_BINARY_DIR}/generated/core/version.h" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ecvpose/core)

set(ecv_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/ecvpose)
install(EXPORT ecvposeTargets NAMESPACE ecvpose:: DESTINATION ${ecv_cmake_dir})
configure_package_config_file(cmake/ecvposeConfig.cmake.in "${PROJECT_BINARY_DIR}/ecvposeConfig.cmake"
                              INSTALL_DESTINATION ${ecv_cmake_dir})
write_basic_package_version_file("${PROJECT_BINARY_DIR}/ecvposeConfigVersion.cmake"
                                 COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/ecvposeConfig.cmake" "${PROJECT_BINARY_DIR}/ecvposeConfigVersion.cmake"
        DESTINATION ${ecv_cmake_dir})
install(FILES LICENSE README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/ecvpose)
