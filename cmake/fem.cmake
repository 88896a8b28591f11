# fem/: energy terms and their assembly (TBB-parallel over elements).
find_package(TBB REQUIRED)

shapectl_area(fem)
target_link_libraries(shapectl_fem PUBLIC shapectl_mesh PRIVATE TBB::tbb)

shapectl_tests(fem shapectl_fem TBB::tbb)
