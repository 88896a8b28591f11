# web/: the browser GUI. Its end-to-end tests and the WebSocket fuzz test (Node;
# web/node_modules from `npm ci`) run the CLI's server.
# They are part of the test command: missing tools stop the configure instead of silently
# dropping the tests (scripts/setup.sh installs them first). SHAPECTL_WEB_TESTS=OFF opts out.
option(SHAPECTL_WEB_TESTS "Register the browser and WebSocket fuzz tests (needs node, npm ci, chromium)" ON)
if(NOT SHAPECTL_BUILD_TESTS OR NOT SHAPECTL_WEB_TESTS)
  return()
endif()
find_program(NODE_EXECUTABLE node)
if(NOT NODE_EXECUTABLE)
  message(FATAL_ERROR "node not found: the browser tests need it (apt-get install nodejs npm, "
                      "or run scripts/setup.sh; -DSHAPECTL_WEB_TESTS=OFF to build without them)")
endif()
if(NOT EXISTS ${PROJECT_SOURCE_DIR}/web/node_modules/playwright-core/index.mjs)
  message(FATAL_ERROR "web/node_modules is missing: run `npm ci` in web/ (scripts/setup.sh does) "
                      "or configure with -DSHAPECTL_WEB_TESTS=OFF")
endif()
if(NOT EXISTS /usr/bin/chromium)
  message(FATAL_ERROR "/usr/bin/chromium is missing: apt-get install chromium "
                      "or configure with -DSHAPECTL_WEB_TESTS=OFF")
endif()
foreach(script gui_e2e ws_fuzz robot_link real_object units robot_visuals targets targets_files panel robot_meshes status_jog
               panel_controls contacts self_contacts occlusion unreachable)
  add_test(NAME web_${script}
    COMMAND ${NODE_EXECUTABLE} --test --test-reporter=spec ${PROJECT_SOURCE_DIR}/tests/web/${script}.test.mjs)
  set_tests_properties(web_${script} PROPERTIES TIMEOUT 300
    ENVIRONMENT "SHAPECTL_CLI=$<TARGET_FILE:shapectl_cli>;SHAPECTL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endforeach()
