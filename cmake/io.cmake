# io/: scene, targets and result JSON, VTU, InputError.
shapectl_area(io)
target_link_libraries(shapectl_io PUBLIC nlohmann_json::nlohmann_json)

shapectl_tests(io shapectl_io)
