# cmake --install: the three library layers (static), the public headers and the CMake package
# bodypoint (bodypointConfig.cmake with its version file), so that a program outside the tree writes
#   find_package(bodypoint 0.1 REQUIRED)
#   target_link_libraries(app PRIVATE bodypoint::bodypoint)
# The public headers are the API and what it exposes; the rest (kernels, drivers, the force field, the
# Kepler solver, detail/, the commands' helpers: io, scenes, observables, batch, threads, order_fit, the
# accuracy layer's search) stays inside.
include(CMakePackageConfigHelpers)

set_target_properties(bodypoint_core PROPERTIES EXPORT_NAME core)
set_target_properties(bodypoint_adaptive PROPERTIES EXPORT_NAME adaptive)
install(TARGETS bodypoint_core bodypoint_adaptive bodypoint
        EXPORT bodypointTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES
          ${PROJECT_SOURCE_DIR}/lib/api/bodypoint/bodypoint.hpp
          ${PROJECT_SOURCE_DIR}/lib/api/bodypoint/methods.hpp
          ${PROJECT_SOURCE_DIR}/lib/api/bodypoint/record.hpp
          ${PROJECT_SOURCE_DIR}/lib/api/bodypoint/sweep.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/invariant_stats.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/invariants.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/model.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/drivers/bodypoint/run.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/scattering.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/scene_file.hpp
          # The independent references and the equations of motion as an ODE system (a program drives
          # Boost.Odeint with PreciseEquations; neither header includes Boost).
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/reference.hpp
          ${PROJECT_SOURCE_DIR}/lib/core/model/bodypoint/rhs.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bodypoint)

set(BODYPOINT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/bodypoint)
install(EXPORT bodypointTargets NAMESPACE bodypoint:: DESTINATION ${BODYPOINT_CMAKE_DIR})
# BODYPOINT_INSTALLED_GSL (lib/CMakeLists.txt): the package then asks for GSL too.
configure_package_config_file(${PROJECT_SOURCE_DIR}/lib/cmake/bodypointConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/bodypointConfig.cmake
                              INSTALL_DESTINATION ${BODYPOINT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bodypointConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bodypointConfig.cmake ${PROJECT_BINARY_DIR}/bodypointConfigVersion.cmake
        DESTINATION ${BODYPOINT_CMAKE_DIR})
