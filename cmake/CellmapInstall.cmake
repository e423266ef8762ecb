# SPDX-License-Identifier: Apache-2.0
# Installs cellmap for use outside the tree: the stage libraries with their public headers, the generated DDS
# types, the `cellmap` and `cellmapd` programs, the daemon's configuration, the systemd unit, and a CMake
# package (cellmapConfig.cmake) exporting
#   cellmap::cellmap  every stage (the umbrella target `cellmap`)
#   cellmap::client   what a planner needs: subscribe to a cell (transport), environments, collision, paths
#   cellmap::<stage>  each stage library, e.g. cellmap::transport
# in two components: `client` (cellmap::client and the stages it links: needs Eigen, Cyclone DDS and OpenSSL
# only) and `mapper` (every other stage; needs PCL, OctoMap, urdfdom, assimp, yaml-cpp and the camera
# libraries).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CELLMAP_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/cellmap)
set(CELLMAP_INSTALL_CONFIGDIR ${CMAKE_INSTALL_SYSCONFDIR}/cellmap)

# The planner's slice of the library.
add_library(cellmap_client INTERFACE)
target_link_libraries(cellmap_client INTERFACE cellmap_transport cellmap_environment cellmap_planning
                      cellmap_collision)
add_library(cellmap::client ALIAS cellmap_client)
add_library(cellmap::cellmap ALIAS cellmap)

# The stages are what `cellmap` links (cellmap_stage adds each); links made from other directories carry
# "::@(...)" scope markers in that list, which are not targets.
get_target_property(CELLMAP_LINKED cellmap INTERFACE_LINK_LIBRARIES)
set(CELLMAP_STAGES "")
foreach(item IN LISTS CELLMAP_LINKED)
  if(item MATCHES "^cellmap_" AND TARGET ${item})
    list(APPEND CELLMAP_STAGES ${item})
  endif()
endforeach()
foreach(stage IN LISTS CELLMAP_STAGES)
  string(REGEX REPLACE "^cellmap_" "" short ${stage})
  set_target_properties(${stage} PROPERTIES EXPORT_NAME ${short})
  target_include_directories(${stage} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
endforeach()
# Our prebuilt stages were compiled with this (PCL 1.13 is C++14, see the top CMakeLists.txt); a consumer
# that allocates our Eigen-holding types must agree, or new/delete of over-aligned types mismatch.
target_compile_definitions(cellmap_common INTERFACE $<INSTALL_INTERFACE:EIGEN_HAS_CXX17_OVERALIGN=0>)
set_target_properties(cellmap_client PROPERTIES EXPORT_NAME client)
set_target_properties(cellmap_pcl PROPERTIES EXPORT_NAME pcl)
set_target_properties(cellmap_idl PROPERTIES EXPORT_NAME idl)
set_target_properties(cellmap_ros2_idl PROPERTIES EXPORT_NAME ros2_idl)

# The client component: cellmap_client and every cellmap target it links, directly or through a stage.
set(CELLMAP_CLIENT_TARGETS "")
set(pending cellmap_client)
while(pending)
  list(POP_FRONT pending target)
  if(target IN_LIST CELLMAP_CLIENT_TARGETS)
    continue()
  endif()
  list(APPEND CELLMAP_CLIENT_TARGETS ${target})
  get_target_property(links ${target} INTERFACE_LINK_LIBRARIES)
  foreach(link IN LISTS links)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" link "${link}")
    if(link MATCHES "^cellmap_" AND TARGET ${link})
      list(APPEND pending ${link})
    endif()
  endforeach()
endwhile()
set(CELLMAP_MAPPER_TARGETS cellmap cellmap_pcl cellmap_idl cellmap_ros2_idl ${CELLMAP_STAGES})
list(REMOVE_ITEM CELLMAP_MAPPER_TARGETS ${CELLMAP_CLIENT_TARGETS})

install(TARGETS ${CELLMAP_CLIENT_TARGETS}
        EXPORT cellmapClientTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS ${CELLMAP_MAPPER_TARGETS}
        EXPORT cellmapTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# Each stage's public headers (its include/ folder; internal headers beside the sources stay behind).
foreach(stage IN LISTS CELLMAP_STAGES)
  get_target_property(stage_dir ${stage} SOURCE_DIR)
  install(DIRECTORY ${stage_dir}/include/cellmap DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
# The DDS types for programs that read the topics without the client library (other vendors, ROS 2 tools).
install(FILES ${PROJECT_SOURCE_DIR}/idl/cellmap.idl ${PROJECT_BINARY_DIR}/idl/cellmap.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cellmap/idl)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/idl/ros2 DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cellmap/idl
        FILES_MATCHING PATTERN "*.idl")

install(EXPORT cellmapClientTargets NAMESPACE cellmap:: DESTINATION ${CELLMAP_INSTALL_CMAKEDIR})
install(EXPORT cellmapTargets NAMESPACE cellmap:: DESTINATION ${CELLMAP_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/cellmapConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cellmapConfig.cmake
  INSTALL_DESTINATION ${CELLMAP_INSTALL_CMAKEDIR}
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR CELLMAP_INSTALL_CONFIGDIR)
# 0.x: a minor release may break the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cellmapConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cellmapConfig.cmake ${PROJECT_BINARY_DIR}/cellmapConfigVersion.cmake
        DESTINATION ${CELLMAP_INSTALL_CMAKEDIR})

# Programs, configuration and the service.
install(TARGETS cellmap_cli cellmapd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Every shipped cell with what it names (scenes, robots and their meshes), laid out as in config/: paths in
# these files are relative to the file, so each runs from the install as it does from the source tree.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION ${CELLMAP_INSTALL_CONFIGDIR})
# The unit in scripts/ names the /usr/local paths; the installed one names where this install put things
# (decided at install time: `cmake --install --prefix` may differ from the configured prefix).
install(CODE "set(CELLMAPD_UNIT_IN [[${PROJECT_SOURCE_DIR}/scripts/cellmapd.service]])
  set(CELLMAPD_UNIT_OUT [[${PROJECT_BINARY_DIR}/cellmapd.service]])
  set(CELLMAPD_BINDIR [[${CMAKE_INSTALL_BINDIR}]])
  set(CELLMAPD_SYSCONFDIR [[${CMAKE_INSTALL_SYSCONFDIR}]])")
install(SCRIPT ${PROJECT_SOURCE_DIR}/cmake/InstallUnit.cmake)
install(FILES ${PROJECT_BINARY_DIR}/cellmapd.service DESTINATION lib/systemd/system)  # where systemd looks; never the multiarch libdir
