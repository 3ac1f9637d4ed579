# SPDX-License-Identifier: Apache-2.0
# Manual pages of the packaged programs (fusedet, fusedetd), made from their --help and the
# project version (not --version: its second line names the build machine's vector path) by
# Debian's help2man at build time; the date is the Debian changelog's (SOURCE_DATE_EPOCH), so
# the pages are the same on every build. The build tree's default config path in them is replaced
# by the installed one at install time (cmake/install_system_files.cmake), which also compresses
# them into <prefix>/share/man/man1. Without help2man (scripts/deps installs it) there are none,
# and tests/tools/check_package.sh's lintian run says so. In a cross build (the arm64 package,
# scripts/arm64-package) help2man runs the programs through CMAKE_CROSSCOMPILING_EMULATOR, by a
# script of the program's name (help2man takes the program name from the file it runs).
find_program(HELP2MAN help2man)
if(NOT HELP2MAN)
  message(WARNING "help2man not found: no manual pages for fusedet and fusedetd (scripts/deps installs it)")
  return()
endif()
set(FUSEDET_MAN_DIR ${PROJECT_BINARY_DIR}/man)
set(_changelog ${PROJECT_SOURCE_DIR}/cmake/deb/changelog)
set(_pages)
foreach(_program fusedet fusedetd)
  if(_program STREQUAL fusedet)
    set(_what "camera + tilting laser object detection: devices, training, evaluation, query client")
  else()
    set(_what "fusedet perception service (camera + tilting laser -> detections on a Unix socket)")
  endif()
  set(_page ${FUSEDET_MAN_DIR}/${_program}.1)
  set(_run $<TARGET_FILE:${_program}>)
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    set(_run ${FUSEDET_MAN_DIR}/emulated/${_program})
    list(JOIN CMAKE_CROSSCOMPILING_EMULATOR "' '" _emulator)
    file(GENERATE OUTPUT ${_run} CONTENT "#!/bin/sh\nexec '${_emulator}' '$<TARGET_FILE:${_program}>' \"$@\"\n"
         FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
  endif()
  add_custom_command(OUTPUT ${_page}
                     COMMAND ${CMAKE_COMMAND} -E make_directory ${FUSEDET_MAN_DIR}
                     COMMAND sh -c "SOURCE_DATE_EPOCH=$(dpkg-parsechangelog -STimestamp -l '${_changelog}') \
exec '${HELP2MAN}' --no-info --no-discard-stderr --version-string '${PROJECT_VERSION}' --section 1 --name '${_what}' --output '${_page}' '${_run}'"
                     DEPENDS ${_program} ${_changelog} VERBATIM)
  list(APPEND _pages ${_page})
endforeach()
add_custom_target(fusedet_man_pages ALL DEPENDS ${_pages})
