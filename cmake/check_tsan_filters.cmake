# CTest's tsan_filters (cmake/tsan.cmake): every GoogleTest pattern of the tsan label names at
# least one registered test, so a renamed or moved test cannot leave ThreadSanitizer silently.
#   cmake -DBUILD_DIR=... -DFILTERS="a.*:b.c*" -P check_tsan_filters.cmake
execute_process(COMMAND ${CMAKE_CTEST_COMMAND} -N -L tsan WORKING_DIRECTORY ${BUILD_DIR}
                OUTPUT_VARIABLE listed RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "ctest -N -L tsan failed in ${BUILD_DIR}")
endif()
string(REPLACE ":" ";" patterns "${FILTERS}")
set(unmatched "")
foreach(pattern IN LISTS patterns)
  string(REPLACE "." "\\." regex "${pattern}")
  string(REPLACE "*" ".*" regex "${regex}")
  if(NOT listed MATCHES "Test +#[0-9]+: ${regex}\n")
    list(APPEND unmatched "${pattern}")
  endif()
endforeach()
if(unmatched)
  message(FATAL_ERROR "tsan filters that match no test: ${unmatched}")
endif()
list(LENGTH patterns count)
message(STATUS "each of the ${count} tsan filters matches a test")
