# Benchmarks: bench/<area>_bench.cpp, one binary each; KDL is the field's reference for
# kinematics speed.
if(NOT SHAPECTL_BUILD_BENCHMARKS)
  return()
endif()
find_package(benchmark REQUIRED)
find_package(orocos_kdl REQUIRED)

file(GLOB bench_sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/bench/*_bench.cpp)
foreach(src ${bench_sources})
  get_filename_component(name ${src} NAME_WE)
  add_executable(${name} ${src})
  target_link_libraries(${name} PRIVATE shapectl benchmark::benchmark ${orocos_kdl_LIBRARIES})
  target_include_directories(${name} PRIVATE ${orocos_kdl_INCLUDE_DIRS})
  target_compile_definitions(${name} PRIVATE SHAPECTL_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endforeach()
