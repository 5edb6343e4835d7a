# node >= 18 and npm, for the JavaScript parts (viewer/, tests/gltf/): sets KEYANIM_NODE and
# KEYANIM_NPM (found programs) and KEYANIM_NODE_FOUND (both present, node recent enough).
find_program(KEYANIM_NODE node)
find_program(KEYANIM_NPM npm)
set(KEYANIM_NODE_FOUND OFF)
if(KEYANIM_NODE AND KEYANIM_NPM)
  execute_process(COMMAND ${KEYANIM_NODE} --version OUTPUT_VARIABLE _keyanim_node_version
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  string(REGEX REPLACE "^v" "" _keyanim_node_version "${_keyanim_node_version}")
  if(_keyanim_node_version VERSION_GREATER_EQUAL 18)
    set(KEYANIM_NODE_FOUND ON)
  endif()
endif()
