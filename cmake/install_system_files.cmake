# SPDX-License-Identifier: Apache-2.0
# Runs at install time (install(SCRIPT), component runtime): the files whose place or content
# depends on the prefix given to `cmake --install --prefix P` or cpack - CMAKE_INSTALL_PREFIX here -
# rather than the one given at configure time. For the prefix /usr the FHS places apply: the
# configuration in /etc and (Debian 12) the units in /lib/systemd/system. file(INSTALL) honours
# DESTDIR, which is how cpack stages the package.
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(_etc /etc)
  set(_units /lib/systemd/system)
else()
  set(_etc ${CMAKE_INSTALL_PREFIX}/etc)
  set(_units ${CMAKE_INSTALL_PREFIX}/lib/systemd/system)
endif()

# The unit templates' variables, for this prefix (ExecStart, --config, Documentation=).
set(CMAKE_INSTALL_FULL_BINDIR ${CMAKE_INSTALL_PREFIX}/${FUSEDET_BINDIR})
set(CMAKE_INSTALL_FULL_SYSCONFDIR ${_etc})
set(CMAKE_INSTALL_FULL_DOCDIR ${CMAKE_INSTALL_PREFIX}/${FUSEDET_DOCDIR})
set(_service ${FUSEDET_BINARY_DIR}/systemd/installed/fusedetd.service)
configure_file(${FUSEDET_SOURCE_DIR}/systemd/fusedetd.service.in ${_service} @ONLY)
set(_record ${FUSEDET_BINARY_DIR}/systemd/installed/fusedet-record.service)
configure_file(${FUSEDET_SOURCE_DIR}/systemd/fusedet-record.service.in ${_record} @ONLY)

file(INSTALL DESTINATION ${_etc}/fusedet TYPE FILE FILES ${FUSEDET_SOURCE_DIR}/config/fusedet.yaml)
file(INSTALL DESTINATION ${_units} TYPE FILE FILES ${_service} ${_record} ${FUSEDET_SOURCE_DIR}/systemd/fusedetd.socket)
# The group of socket clients; systemd-sysusers creates it (the package's postinst runs it).
file(INSTALL DESTINATION ${CMAKE_INSTALL_PREFIX}/lib/sysusers.d TYPE FILE
     FILES ${FUSEDET_SOURCE_DIR}/systemd/fusedet.sysusers RENAME fusedet.conf)

# The manual pages (cmake/FusedetManPages.cmake; none without help2man): the build tree's default
# config path as the installed fusedetd sees it, gzip -9n as Debian wants them.
if(FUSEDET_MAN_DIR AND EXISTS ${FUSEDET_MAN_DIR}/fusedetd.1)
  foreach(_page fusedet.1 fusedetd.1)
    file(READ ${FUSEDET_MAN_DIR}/${_page} _text)
    string(REPLACE "${FUSEDET_BINARY_DIR}/etc/" "${_etc}/" _text "${_text}")
    # help2man writes each '-' as '\-' (roff): a build folder with a '-' in its path, e.g. a clone
    # in /tmp/fresh-clone.X, appears in that form.
    string(REPLACE "-" "\\-" _binary_roff "${FUSEDET_BINARY_DIR}")
    string(REPLACE "${_binary_roff}/etc/" "${_etc}/" _text "${_text}")
    file(WRITE ${FUSEDET_BINARY_DIR}/man/installed/${_page} "${_text}")
    execute_process(COMMAND gzip -9n -f ${FUSEDET_BINARY_DIR}/man/installed/${_page} RESULT_VARIABLE _rc)
    if(NOT _rc EQUAL 0)
      message(FATAL_ERROR "gzip ${FUSEDET_BINARY_DIR}/man/installed/${_page} failed")
    endif()
    file(INSTALL DESTINATION ${CMAKE_INSTALL_PREFIX}/${FUSEDET_MANDIR}/man1 TYPE FILE
         FILES ${FUSEDET_BINARY_DIR}/man/installed/${_page}.gz)
  endforeach()
endif()
