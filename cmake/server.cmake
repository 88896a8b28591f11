# server/: HTTP + WebSocket GUI backend (Boost.Beast, header-only).
find_package(Boost 1.74 REQUIRED)
find_package(Threads REQUIRED)

shapectl_area(server)
target_link_libraries(shapectl_server PUBLIC shapectl_calib shapectl_control nlohmann_json::nlohmann_json
                      PRIVATE shapectl_io shapectl_link shapectl_robot shapectl_scene_io Boost::headers Threads::Threads)
target_compile_definitions(shapectl_server PRIVATE SHAPECTL_SOURCE_DIR="${PROJECT_SOURCE_DIR}")

shapectl_tests(server shapectl_server shapectl_link shapectl_scene_io Boost::headers)
if(TARGET server_tests)
  add_dependencies(server_tests shapectl_cli)  # serve_cli_test runs the CLI
endif()
