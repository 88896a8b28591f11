# runtime/: the process-wide tuning policy (thread counts, OpenBLAS's idle threads, the heap),
# applied by every program that runs the solvers. OpenBLAS is looked up weak: not linked here.
find_package(TBB REQUIRED)
find_package(BLAS REQUIRED)  # the tests call it to see its threads

shapectl_area(runtime)
target_link_libraries(shapectl_runtime PRIVATE shapectl_io TBB::tbb)

shapectl_tests(runtime shapectl_runtime TBB::tbb ${BLAS_LIBRARIES})
