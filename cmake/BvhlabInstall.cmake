# cmake --install exports a package: find_package(bvhlab) + target_link_libraries(x bvhlab::bvhlab).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(BVHLAB_INSTALL_TARGETS bvhlab bvhlab_volumes bvhlab_bvh bvhlab_mesh_io bvhlab_adb bvhlab_traversal)
install(TARGETS ${BVHLAB_INSTALL_TARGETS} EXPORT bvhlabTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(folder volumes bvh adb traversal)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bvhlab/${folder}
    FILES_MATCHING PATTERN "*.hpp" PATTERN "*_internal.hpp" EXCLUDE)
endforeach()
install(EXPORT bvhlabTargets NAMESPACE bvhlab:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bvhlab)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bvhlabConfig.cmake.in
  ${PROJECT_BINARY_DIR}/bvhlabConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bvhlab)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bvhlabConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bvhlabConfig.cmake ${PROJECT_BINARY_DIR}/bvhlabConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bvhlab)
# The command line beside the libraries (it reads the bundled meshes and its cache below this build's
# source and build folders).
if(TARGET bvhlab_cli)
  install(TARGETS bvhlab_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
