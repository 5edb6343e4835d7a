# The README's C++ example ("The library in a few lines") compiled and run as written: its
# #include lines at the top of a file, the rest inside main(), run from the repository root.
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/README.md)
file(READ ${PROJECT_SOURCE_DIR}/README.md _readme)
string(FIND "${_readme}" "## The library in a few lines" _at)
string(SUBSTRING "${_readme}" ${_at} -1 _readme)
string(FIND "${_readme}" "```cpp\n" _start)
math(EXPR _start "${_start} + 7")
string(SUBSTRING "${_readme}" ${_start} -1 _readme)
string(FIND "${_readme}" "```" _end)
string(SUBSTRING "${_readme}" 0 ${_end} _code)
string(REGEX MATCHALL "#include <[^>\n]+>" _includes "${_code}")
string(REGEX REPLACE "#include <[^>\n]+>\n" "" _body "${_code}")
string(REPLACE ";" "\n" _includes "${_includes}")
file(CONFIGURE OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp
     CONTENT "// Generated from README.md by tests/readme_example.cmake.\n${_includes}\n\nint main() {\n${_body}  return 0;\n}\n"
     @ONLY)
add_executable(readme_example ${CMAKE_CURRENT_BINARY_DIR}/readme_example.cpp)
target_link_libraries(readme_example PRIVATE keyanim::keyanim)
target_compile_options(readme_example PRIVATE ${KEYANIM_WARNINGS})
add_test(NAME readme_cpp_example COMMAND readme_example WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(readme_cpp_example PROPERTIES PASS_REGULAR_EXPRESSION "keys, error max [0-9.e-]+ <= tolerance")
