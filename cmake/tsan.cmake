# ThreadSanitizer build of the concurrency tests (issue 33): `ctest -L tsan` in a tree configured
# with -DSHAPECTL_TSAN=ON (scripts/test.sh makes build-tsan). Only the test binaries below are
# built (target tsan_tests), and of them only the tests that run code on more than one thread:
# the two-thread kernels (band and supernodal factors, CHOLMOD analysis beside the band's),
# statics' analysis beside assembly, the element loops, the controller and online calibration
# threads, the link and the server. Left out: tests with wall-clock bounds or that spawn the CLI
# (ServeStop, EgmAdversarial, serve_cli, and the two named below), since TSan runs code 5-15x
# slower; a wait that only keeps a broken thread from hanging a test is 20x longer under TSan
# (tests/support/wait_bound.hpp).
option(SHAPECTL_TSAN "ThreadSanitizer build of the concurrency tests only (ctest -L tsan)" OFF)
if(NOT SHAPECTL_TSAN)
  return()
endif()
if(SHAPECTL_NATIVE)
  message(FATAL_ERROR "SHAPECTL_TSAN builds portable code: configure it with SHAPECTL_NATIVE OFF")
endif()
# -O1: a third less compile time than -O3, the usual optimization for TSan; -g1: source lines
# in the reports.
set(CMAKE_CXX_FLAGS_RELEASE "-O1 -g1 -DNDEBUG")
add_compile_options(-fsanitize=thread)
# GCC 12 refuses a precompiled header under -fsanitize=thread (-Winvalid-pch): none is built.
set(CMAKE_DISABLE_PRECOMPILE_HEADERS ON)
add_link_options(-fsanitize=thread)

# GoogleTest filters by area (test binary).
set(shapectl_tsan_fem "NeoHookean.*:GradientGather.*")
set(shapectl_tsan_linalg "SupernodalLlt.*Subtrees*:FactorBand.*:BandCholesky.*:SerialOpenMp.*:SparseCholesky.AutomaticChoice*")
set(shapectl_tsan_sim "ObjectState.TwoThreads*:*StaticsEachSolver.ClampedBar*:Statics.ChordSteps*")
set(shapectl_tsan_control "Controller.*")
# Not CancelStopsARunningCalibrationAtItsNextCheck: it bounds the cancel by 1 s of wall clock.
set(shapectl_tsan_calib "OnlineCalibrationTest.The*:OnlineCalibrationTest.ANewModel*:OnlineCalibrationTest.ARobotCreeping*:OnlineCalibrationTest.TooFew*:OnlineCalibrationTest.AFitOfNothing*")
# Not EgmLoopback.ArmedMotion...: it bounds the watchdog's disarm by 0.2 s of wall clock.
set(shapectl_tsan_link "SimLink.*:EgmLoopback.BadDatagrams*:EgmLoopback.MeasuresTheFeedback*")
set(shapectl_tsan_server "SessionTest.*:SessionWorld.*:ServerClose.*")

# A report fails its test (exit code 66). tests/tsan.supp names what is not ours. OpenMP (in
# CHOLMOD) and OpenBLAS on one thread each: their own threads are uninstrumented, and the many
# suppressed reports they raise made a test run for minutes; our threads are TBB's.
set(shapectl_tsan_environment
  "TSAN_OPTIONS=halt_on_error=1 second_deadlock_stack=1 suppressions=${PROJECT_SOURCE_DIR}/tests/tsan.supp"
  OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1)
add_custom_target(tsan_tests)
# Each filter names a test: else a renamed or moved test would leave TSan without a word.
add_test(NAME tsan_filters
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${PROJECT_BINARY_DIR}
          "-DFILTERS=$<JOIN:$<TARGET_PROPERTY:tsan_tests,shapectl_filters>,:>"
          -P ${PROJECT_SOURCE_DIR}/cmake/check_tsan_filters.cmake)
set_tests_properties(tsan_filters PROPERTIES LABELS tsan)

# Called by shapectl_tests for ${area}_tests in place of its usual registration.
function(shapectl_tsan_tests area)
  add_dependencies(tsan_tests ${area}_tests)
  set_property(TARGET tsan_tests APPEND PROPERTY shapectl_filters ${shapectl_tsan_${area}})
  gtest_discover_tests(${area}_tests DISCOVERY_TIMEOUT 120 TEST_FILTER "${shapectl_tsan_${area}}"
    PROPERTIES TIMEOUT 900 LABELS tsan ENVIRONMENT "${shapectl_tsan_environment}")
endfunction()
