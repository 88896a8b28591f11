# server/: HTTP + WebSocket GUI backend (Boost.Beast, header-only).
find_package(Boost 1.74 REQUIRED)
find_package(Threads REQUIRED)

shapectl_area(server)
target_link_libraries(shapectl_server PUBLIC shapectl_calib shapectl_contact shapectl_control nlohmann_json::nlohmann_json
                      PRIVATE shapectl_io shapectl_link shapectl_robot shapectl_runtime shapectl_scene_io shapectl_sim Boost::headers Threads::Threads)
target_compile_definitions(shapectl_server PRIVATE SHAPECTL_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

shapectl_tests(server shapectl_server shapectl_link shapectl_scene_io Boost::headers)
if(TARGET server_tests AND NOT SHAPECTL_TSAN)  # the TSan tree runs no CLI
  add_dependencies(server_tests shapectl_cli)  # serve_cli_test runs the CLI
endif()

# The drag soak (issue 32, item 5): its own binary, not a discovered GoogleTest, so CTest can
# label it, give it a longer timeout and start it first (COST). SHAPECTL_SOAK_SECONDS (default
# 600) sets its duration; `ctest -L soak` runs it alone, `ctest -LE soak` everything else.
if(SHAPECTL_BUILD_TESTS AND NOT SHAPECTL_TSAN)
  add_executable(drag_soak ${PROJECT_SOURCE_DIR}/tests/server/drag_soak.cpp)
  target_link_libraries(drag_soak PRIVATE shapectl_server shapectl_link shapectl_scene_io
                        shapectl_test_support GTest::gtest_main)
  target_precompile_headers(drag_soak REUSE_FROM shapectl_test_support)
  add_test(NAME drag_soak COMMAND drag_soak)
  set_tests_properties(drag_soak PROPERTIES LABELS soak COST 10000 TIMEOUT 1200)
endif()
