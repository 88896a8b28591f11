# sim/: grip coupling and statics; the Hessian's factorization is linalg/'s.
find_package(TBB REQUIRED)  # statics analyses the pattern while it assembles

shapectl_area(sim)
target_link_libraries(shapectl_sim
                      PUBLIC shapectl_contact shapectl_fem shapectl_linalg shapectl_mesh shapectl_robot
                      PRIVATE shapectl_io TBB::tbb)

shapectl_tests(sim shapectl_sim)
