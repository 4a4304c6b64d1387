# Install rules of the package: RubbleConfig.cmake + version file + exported targets (Rubble::rubble,
# Rubble::bullet) under lib/cmake/Rubble, and rubble.pc / rubble-bullet.pc under lib/pkgconfig.
include(CMakePackageConfigHelpers)
set(RUBBLE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/Rubble)

install(EXPORT RubbleTargets NAMESPACE Rubble:: DESTINATION ${RUBBLE_CMAKE_DIR} COMPONENT development)
if(TARGET rubble_bullet_shared)
    install(EXPORT RubbleBulletTargets NAMESPACE Rubble:: DESTINATION ${RUBBLE_CMAKE_DIR}
        COMPONENT development)
endif()
configure_package_config_file(cmake/RubbleConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/RubbleConfig.cmake
    INSTALL_DESTINATION ${RUBBLE_CMAKE_DIR})
# 0.x: a new minor version may break the API.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/RubbleConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/RubbleConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/RubbleConfigVersion.cmake
    DESTINATION ${RUBBLE_CMAKE_DIR} COMPONENT development)

# pkg-config files locate the prefix from their own place (${pcfiledir}), so that `cmake --install --prefix P`
# needs no reconfigure. Only shared libraries are installed, so there is no Libs.private.
file(RELATIVE_PATH RUBBLE_PC_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" RUBBLE_PC_PREFIX "${RUBBLE_PC_PREFIX}")
set(RUBBLE_PC_FILES rubble)
if(TARGET rubble_bullet_shared)
    list(APPEND RUBBLE_PC_FILES rubble-bullet)
endif()
foreach(pc ${RUBBLE_PC_FILES})
    configure_file(cmake/${pc}.pc.in ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc @ONLY)
    install(FILES ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
        COMPONENT development)
endforeach()
