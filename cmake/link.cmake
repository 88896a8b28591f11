# link/: robot streaming (EGM protocol code generated from proto/egm.proto with Debian's
# protoc), the motion governor.
find_package(Protobuf REQUIRED)

set(egm_proto ${PROJECT_SOURCE_DIR}/proto/egm.proto)
set(egm_generated ${CMAKE_CURRENT_BINARY_DIR}/generated/egm)
add_custom_command(
  OUTPUT ${egm_generated}/egm.pb.cc ${egm_generated}/egm.pb.h
  COMMAND ${CMAKE_COMMAND} -E make_directory ${egm_generated}
  COMMAND protobuf::protoc --cpp_out=${egm_generated} -I ${PROJECT_SOURCE_DIR}/proto ${egm_proto}
  DEPENDS ${egm_proto} protobuf::protoc
  COMMENT "Generating EGM protocol code from proto/egm.proto")

shapectl_area(link)
target_link_libraries(shapectl_link PUBLIC shapectl_io nlohmann_json::nlohmann_json
                      PRIVATE shapectl_robot protobuf::libprotobuf)
target_sources(shapectl_link PRIVATE ${egm_generated}/egm.pb.cc)
# Only the codec sees the generated types; nothing public depends on them.
target_include_directories(shapectl_link PRIVATE ${egm_generated})
set_source_files_properties(${egm_generated}/egm.pb.cc PROPERTIES COMPILE_OPTIONS "-w")
# Its sources share helper names in anonymous namespaces: one unit each.
set_target_properties(shapectl_link PROPERTIES UNITY_BUILD OFF)

shapectl_tests(link shapectl_link)
