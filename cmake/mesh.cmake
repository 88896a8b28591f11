# mesh/: TetMesh and its readers; surface meshes are tetrahedralised with TetGen.
find_library(TETGEN_LIB tet REQUIRED)

shapectl_area(mesh)
target_link_libraries(shapectl_mesh PRIVATE shapectl_io ${TETGEN_LIB})
target_compile_definitions(shapectl_mesh PRIVATE TETLIBRARY)  # tetgen.h as a library

shapectl_tests(mesh shapectl_mesh)
