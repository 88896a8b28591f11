# contact/: obstacles and the contact barrier energy against them (issue 34).
shapectl_area(contact)
target_link_libraries(shapectl_contact PUBLIC shapectl_fem shapectl_mesh)

shapectl_tests(contact shapectl_contact)
