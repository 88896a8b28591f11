# server/: HTTP + WebSocket GUI backend (Boost.Beast, header-only), its tests and the browser tests.
find_package(Boost 1.74 REQUIRED)
find_package(Threads REQUIRED)
shapectl_area(server shapectl_control Boost::headers Threads::Threads)
target_compile_definitions(shapectl_server PRIVATE SHAPECTL_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_link_libraries(shapectl INTERFACE shapectl_server)

# Tests: the top-level file defines shapectl_tests and enables testing after including this one.
function(shapectl_server_tests)
  shapectl_tests(server shapectl_server)
  add_dependencies(server_tests shapectl_cli)  # serve_cli_test runs the CLI
endfunction()
cmake_language(DEFER CALL shapectl_server_tests)

# Browser end-to-end tests and the WebSocket fuzz test (Node; web/node_modules from `npm ci`).
find_program(NODE_EXECUTABLE node)
function(shapectl_web_tests)
  if(NOT NODE_EXECUTABLE)
    message(WARNING "node not found: browser and WebSocket fuzz tests are not registered")
    return()
  endif()
  foreach(script gui_e2e ws_fuzz robot_link)
    add_test(NAME web_${script}
      COMMAND ${NODE_EXECUTABLE} --test --test-reporter=spec ${PROJECT_SOURCE_DIR}/tests/web/${script}.test.mjs)
    set_tests_properties(web_${script} PROPERTIES TIMEOUT 300
      ENVIRONMENT "SHAPECTL_CLI=$<TARGET_FILE:shapectl_cli>;SHAPECTL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  endforeach()
endfunction()
cmake_language(DEFER CALL shapectl_web_tests)
