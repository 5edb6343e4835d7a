# Writes the man page keyanim.1 from the built tool's help, with Debian's help2man: the main
# --help gives NAME, SYNOPSIS and DESCRIPTION (commands, global options, exit codes); each
# command's help (without the global part, which the page has once) becomes a subsection of
# COMMANDS: its usage, its paragraphs, its options as tagged paragraphs. Run by
# tools/CMakeLists.txt:  cmake -DKEYANIM=bin -DHELP2MAN=help2man -DOUT=keyanim.1 -P keyanim_man.cmake

# run(VAR args...): VAR = the output of keyanim with these arguments; stops on failure.
function(run var)
  execute_process(COMMAND ${KEYANIM} ${ARGN} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "keyanim ${ARGN} failed: ${rc}")
  endif()
  set(${var} "${out}" PARENT_SCOPE)
endfunction()

# roff(VAR): one command's help text as man(7) markup (every line of text starts with \& so that
# none is taken for a request). Lines are: the usage (its other forms, and their indented
# continuations), option entries ("  -x, --long ARG   text", continued at 20+ spaces), bullets
# ("  - text") and plain paragraph lines.
function(roff var text)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  string(REPLACE ";" "<semicolon>" text "${text}")  # CMake lists split on ';'
  string(REPLACE "\n" ";" lines "${text}")
  set(out "")
  set(state "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^usage: (keyanim [a-z]+) (.*)$")
      string(APPEND out ".PP\n\\fB${CMAKE_MATCH_1}\\fR ${CMAKE_MATCH_2}\n")
      set(state usage)
    elseif(line MATCHES "^  or:  (keyanim [a-z]+) (.*)$")  # another form of the usage
      string(APPEND out ".br\n\\fB${CMAKE_MATCH_1}\\fR ${CMAKE_MATCH_2}\n")
      set(state usage)
    elseif(line MATCHES "^  (\\\\-[^ ].*[^ ])  +([^ ].*)$")
      string(APPEND out ".TP\n\\fB${CMAKE_MATCH_1}\\fR\n\\&${CMAKE_MATCH_2}\n")
      set(state item)
    elseif(line MATCHES "^  \\\\- (.*)$")
      string(APPEND out ".IP \\(bu 2\n\\&${CMAKE_MATCH_1}\n")
      set(state item)
    elseif(line MATCHES "^ +([^ ].*)$" AND state)
      string(APPEND out "\\&${CMAKE_MATCH_1}\n")
    elseif(line STREQUAL "")
      set(state "")
    else()
      if(NOT state STREQUAL "para")
        string(APPEND out ".PP\n")
      endif()
      string(APPEND out "\\&${line}\n")
      set(state para)
    endif()
  endforeach()
  string(REPLACE "<semicolon>" ";" out "${out}")
  set(${var} "${out}" PARENT_SCOPE)
endfunction()

run(main --help)
string(REGEX MATCH "\ncommands:\n(  [^\n]*\n)+" list "${main}")
string(REGEX MATCHALL "\n  [a-z]+ " names "${list}")
set(include "[COMMANDS]\n")
foreach(name IN LISTS names)
  string(STRIP "${name}" name)
  if(name STREQUAL "help")
    continue()
  endif()
  run(text help ${name})
  string(FIND "${text}" "\nglobal options" cut)
  string(SUBSTRING "${text}" 0 ${cut} text)
  roff(text "${text}")
  string(APPEND include ".SS \"keyanim ${name}\"\n${text}")
endforeach()
string(APPEND include "[SEE ALSO]\nThe README and spec/FORMAT.md (the .kanim format) in the keyanim sources.\n")
file(WRITE ${OUT}.h2m "${include}")
execute_process(
  COMMAND ${HELP2MAN} --no-info --section 1 --include ${OUT}.h2m --output ${OUT}
          --name "store skeletal motion as keyframes, rebuilt by Cardinal splines" ${KEYANIM}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man failed: ${rc}")
endif()
