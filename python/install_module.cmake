# Installs the keyanim package (KEYANIM_PYTHON_PACKAGE, the build tree's python/keyanim) into the
# site-packages directory that KEYANIM_PYTHON (/usr/bin/python3) searches for the install
# prefix, by Python's own rules:
#   - the prefix is Python's user base (~/.local): the user site-packages
#     (~/.local/lib/python3.X/site-packages), which Python adds to sys.path by itself;
#   - the prefix holds one of the interpreter's site-packages directories (/usr/local ->
#     /usr/local/lib/python3.X/dist-packages on Debian, /usr -> /usr/lib/python3/dist-packages):
#     that one;
#   - any other prefix: PREFIX/lib/python3.X/site-packages (the posix_prefix scheme), which
#     Python does not search: the install says so and how to set PYTHONPATH.
# KEYANIM_PYTHON_INSTALL_DIR (a cache variable at configure time) overrides this: a path
# relative to the prefix, or absolute.
set(_rules [=[
import os, site, sys, sysconfig
prefix = os.path.realpath(sys.argv[1])
def under(path):
    path = os.path.realpath(path)
    return path.startswith(prefix + os.sep) and os.path.relpath(path, prefix).split(os.sep)[0] == "lib"
if site.ENABLE_USER_SITE and os.path.realpath(site.getuserbase()) == prefix:
    print(site.getusersitepackages() + "\nfound")
    sys.exit(0)
for d in site.getsitepackages():
    if under(d):
        print(d + "\nfound")
        sys.exit(0)
print(sysconfig.get_path("platlib", "posix_prefix", vars={"base": prefix, "platbase": prefix}) + "\nnot searched")
]=])
if(KEYANIM_PYTHON_INSTALL_DIR)
  if(IS_ABSOLUTE "${KEYANIM_PYTHON_INSTALL_DIR}")
    set(_dir "${KEYANIM_PYTHON_INSTALL_DIR}")
  else()
    set(_dir "${CMAKE_INSTALL_PREFIX}/${KEYANIM_PYTHON_INSTALL_DIR}")
  endif()
  set(_searched "given")
else()
  execute_process(COMMAND "${KEYANIM_PYTHON}" -c "${_rules}" "${CMAKE_INSTALL_PREFIX}"
                  OUTPUT_VARIABLE _out RESULT_VARIABLE _rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "keyanim: ${KEYANIM_PYTHON} could not name its site-packages directory for ${CMAKE_INSTALL_PREFIX}")
  endif()
  string(REPLACE "\n" ";" _out "${_out}")
  list(GET _out 0 _dir)
  list(GET _out 1 _searched)
endif()
file(GLOB _files "${KEYANIM_PYTHON_PACKAGE}/*.py" "${KEYANIM_PYTHON_PACKAGE}/_keyanim*.so")
file(INSTALL DESTINATION "${_dir}/keyanim" TYPE FILE FILES ${_files})
if(_searched STREQUAL "not searched")
  message(STATUS "keyanim: the Python module went to ${_dir}, which ${KEYANIM_PYTHON} does not search: "
                 "export PYTHONPATH=\"${_dir}\" (or install with the prefix /usr/local, or ~/.local)")
endif()
