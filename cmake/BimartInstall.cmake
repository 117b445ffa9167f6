# Installation and the CMake package that out-of-tree plug-ins find with find_package(bimart).
include(CMakePackageConfigHelpers)

set_target_properties(bimart_core PROPERTIES EXPORT_NAME core)
set_target_properties(bimart_plugin_entry PROPERTIES EXPORT_NAME plugin_entry)
install(TARGETS bimart_core bimart_plugin_entry EXPORT bimartTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS bimart_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

foreach(dir core stages)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bimart/${dir}
          FILES_MATCHING PATTERN "*.h")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/include/bimart/core/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bimart/core)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/pipelines/ DESTINATION ${CMAKE_INSTALL_DATADIR}/bimart/pipelines)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/bimart/models)

set(config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/bimart)
install(EXPORT bimartTargets NAMESPACE bimart:: DESTINATION ${config_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bimartConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/bimartConfig.cmake INSTALL_DESTINATION ${config_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bimartConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bimartConfig.cmake ${PROJECT_BINARY_DIR}/bimartConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/BimartHelpers.cmake
        DESTINATION ${config_dir})
