# SPDX-License-Identifier: Apache-2.0
# cmake -DCLOSURE=<file> -DTARGET=<name> -DREQUIRED=<a;b> -DFORBIDDEN=<c;d> -P check_link_closure.cmake
# Fails unless the link closure written at configure time (fusedet_link_closure) holds every
# REQUIRED target and no FORBIDDEN one; prints the closure.
cmake_minimum_required(VERSION 3.25)
file(READ "${CLOSURE}" _closure)
string(STRIP "${_closure}" _closure)
message("${TARGET} links: ${_closure}")
set(_bad "")
foreach(_t IN LISTS REQUIRED)
  if(NOT _t IN_LIST _closure)
    list(APPEND _bad "does not link ${_t}")
  endif()
endforeach()
foreach(_t IN LISTS FORBIDDEN)
  if(_t IN_LIST _closure)
    list(APPEND _bad "links ${_t}")
  endif()
endforeach()
if(_bad)
  string(REPLACE ";" ", " _bad "${_bad}")
  message(FATAL_ERROR "${TARGET}: ${_bad}")
endif()
