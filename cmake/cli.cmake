# apps/shapectl: the `shapectl` command, one file per subcommand; tests/cli runs it.
find_package(CLI11 REQUIRED)

file(GLOB app_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/apps/shapectl/*.cpp)
add_executable(shapectl_cli ${app_sources})
set_target_properties(shapectl_cli PROPERTIES OUTPUT_NAME shapectl)
target_link_libraries(shapectl_cli PRIVATE shapectl CLI11::CLI11)
# Unity-built like the areas: every command parses CLI11, nlohmann/json and Eigen. main.cpp
# stays apart, so a new git revision (shapectl_version.hpp) recompiles only main.cpp.
set_target_properties(shapectl_cli PROPERTIES UNITY_BUILD ${SHAPECTL_UNITY_BUILD})
set_source_files_properties(${PROJECT_SOURCE_DIR}/apps/shapectl/main.cpp
                            PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
# `shapectl --version`: the version and the git revision built, refreshed at every build.
add_custom_target(shapectl_version_header
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DVERSION=${PROJECT_VERSION}
          -DOUT=${PROJECT_BINARY_DIR}/generated/shapectl_version.hpp -P ${PROJECT_SOURCE_DIR}/cmake/version.cmake
  BYPRODUCTS ${PROJECT_BINARY_DIR}/generated/shapectl_version.hpp)
add_dependencies(shapectl_cli shapectl_version_header)
target_include_directories(shapectl_cli PRIVATE ${PROJECT_BINARY_DIR}/generated)

shapectl_tests(cli shapectl)
if(TARGET cli_tests)
  add_dependencies(cli_tests shapectl_cli)  # they run the CLI
endif()
