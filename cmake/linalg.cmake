# linalg/: sparse Cholesky of a symmetric positive definite matrix (the statics Hessian) by
# simplicial LDLᵀ (Eigen), a dense band (LAPACK, BLAS-3), our supernodal LLᵀ on CHOLMOD's
# analysis, or CHOLMOD itself. Sees no physics: a SparseMatrix in, a solution out.
find_library(CHOLMOD_LIB cholmod REQUIRED)
find_library(AMD_LIB amd REQUIRED)  # the small matrices' sparse flop estimate
find_path(SUITESPARSE_INCLUDE cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_package(BLAS REQUIRED)
find_package(LAPACK REQUIRED)  # OpenBLAS's: band Cholesky
find_package(TBB REQUIRED)  # the band factorization's two-thread split

shapectl_area(linalg)
target_link_libraries(shapectl_linalg PRIVATE shapectl_runtime TBB::tbb ${CHOLMOD_LIB} ${AMD_LIB} ${LAPACK_LIBRARIES}
                      ${BLAS_LIBRARIES})
target_include_directories(shapectl_linalg PRIVATE ${SUITESPARSE_INCLUDE})

# The tests factor FEM Hessians (ObjectStatics) besides small matrices of their own.
shapectl_tests(linalg shapectl_linalg shapectl_sim)
if(TARGET linalg_tests)  # supernodal_llt_test.cpp makes CHOLMOD factors of its own
  target_include_directories(linalg_tests PRIVATE ${SUITESPARSE_INCLUDE})
  target_link_libraries(linalg_tests PRIVATE ${CHOLMOD_LIB})
endif()
