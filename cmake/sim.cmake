# sim/: grip coupling and statics; sparse Cholesky by CHOLMOD, band Cholesky by LAPACK and BLAS-3.
find_library(CHOLMOD_LIB cholmod REQUIRED)
find_library(AMD_LIB amd REQUIRED)  # the small matrices' sparse flop estimate
find_path(SUITESPARSE_INCLUDE cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_package(BLAS REQUIRED)
find_package(LAPACK REQUIRED)  # OpenBLAS's: band Cholesky
find_package(TBB REQUIRED)  # the band factorization's two-thread split

shapectl_area(sim)
target_link_libraries(shapectl_sim PUBLIC shapectl_fem shapectl_mesh shapectl_robot
                      PRIVATE shapectl_io shapectl_runtime TBB::tbb ${CHOLMOD_LIB} ${AMD_LIB} ${LAPACK_LIBRARIES} ${BLAS_LIBRARIES})
target_include_directories(shapectl_sim PRIVATE ${SUITESPARSE_INCLUDE})

shapectl_tests(sim shapectl_sim)
if(TARGET sim_tests)  # supernodal_llt_test.cpp makes CHOLMOD factors of its own
  target_include_directories(sim_tests PRIVATE ${SUITESPARSE_INCLUDE})
  target_link_libraries(sim_tests PRIVATE ${CHOLMOD_LIB})
endif()
