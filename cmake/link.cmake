# The robot link area: EGM protocol code generated from proto/egm.proto with Debian's protoc,
# the link library, its tests. Included by the top CMakeLists.txt before the CLI target.
find_package(Protobuf REQUIRED)

set(egm_proto ${PROJECT_SOURCE_DIR}/proto/egm.proto)
set(egm_generated ${CMAKE_CURRENT_BINARY_DIR}/generated/egm)
add_custom_command(
  OUTPUT ${egm_generated}/egm.pb.cc ${egm_generated}/egm.pb.h
  COMMAND ${CMAKE_COMMAND} -E make_directory ${egm_generated}
  COMMAND protobuf::protoc --cpp_out=${egm_generated} -I ${PROJECT_SOURCE_DIR}/proto ${egm_proto}
  DEPENDS ${egm_proto} protobuf::protoc
  COMMENT "Generating EGM protocol code from proto/egm.proto")

shapectl_area(link shapectl_control protobuf::libprotobuf)
target_sources(shapectl_link PRIVATE ${egm_generated}/egm.pb.cc)
# Only the codec sees the generated types; nothing public depends on them.
target_include_directories(shapectl_link PRIVATE ${egm_generated})
set_source_files_properties(${egm_generated}/egm.pb.cc PROPERTIES COMPILE_OPTIONS "-w")

target_link_libraries(shapectl INTERFACE shapectl_link)

# shapectl_tests() is defined after this file is included: call it at the end of the directory.
cmake_language(DEFER CALL shapectl_tests link shapectl_link)
