# SPDX-License-Identifier: Apache-2.0
# The Debian package (docs/packaging.md): `cpack -G DEB` in the build folder, or
# `cmake --build build --target package`. It holds the install component `runtime` only, staged
# with DESTDIR under the prefix /usr, so /etc, /lib/systemd/system and /usr/bin are the FHS places
# whatever prefix the build was configured with (cmake/install_system_files.cmake).

# Debian's changelog and copyright belong in /usr/share/doc/fusedet; the changelog gzip'ed without
# a time stamp (reproducible, as dh_compress does).
set(_changelog_gz ${PROJECT_BINARY_DIR}/deb/changelog.gz)
add_custom_command(OUTPUT ${_changelog_gz}
                   COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/deb
                   COMMAND gzip -9n -c ${PROJECT_SOURCE_DIR}/cmake/deb/changelog > ${_changelog_gz}
                   DEPENDS ${PROJECT_SOURCE_DIR}/cmake/deb/changelog VERBATIM)
add_custom_target(fusedet_deb_changelog ALL DEPENDS ${_changelog_gz})
install(FILES ${_changelog_gz} cmake/deb/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME fusedet)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
# Maintainer: the person who builds the package answers for it - DEBFULLNAME / DEBEMAIL as Debian's
# own tools (dch, debmake) take them, else the git identity of the checkout; set
# -DFUSEDET_PACKAGE_MAINTAINER="Name <address>" to choose another.
if(DEFINED ENV{DEBFULLNAME} AND DEFINED ENV{DEBEMAIL})
  set(_maintainer "$ENV{DEBFULLNAME} <$ENV{DEBEMAIL}>")
else()
  find_package(Git QUIET)
  if(GIT_FOUND)
    execute_process(COMMAND ${GIT_EXECUTABLE} config user.name WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                    OUTPUT_VARIABLE _name OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    execute_process(COMMAND ${GIT_EXECUTABLE} config user.email WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                    OUTPUT_VARIABLE _email OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(_name AND _email)
      set(_maintainer "${_name} <${_email}>")
    endif()
  endif()
endif()
set(FUSEDET_PACKAGE_MAINTAINER "${_maintainer}" CACHE STRING "Maintainer field of the Debian package: Name <address>")
if(NOT FUSEDET_PACKAGE_MAINTAINER MATCHES "^[^<>]+ <[^<>@ ]+@[^<>@ ]+>$")
  message(WARNING "FUSEDET_PACKAGE_MAINTAINER '${FUSEDET_PACKAGE_MAINTAINER}' is not 'Name <address>': set it, or "
                  "DEBFULLNAME and DEBEMAIL, before building the Debian package")
endif()
set(CPACK_PACKAGE_CONTACT "${FUSEDET_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "object detection for robots from a colour camera and a tilting laser")
# The synopsis line is CPACK_PACKAGE_DESCRIPTION_SUMMARY; this is the extended description.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "fusedetd fuses a SICK LMS 291 laser scanner nodded by a CANopen tilt motor
with a V4L2 camera into seven-layer stacks, runs one boosted cascade per
object class on them and serves the detections (class, score, image box,
3D position) as newline-delimited JSON on a Unix socket, as a systemd
service with socket activation and a watchdog.
.
The package contains fusedetd, the fusedet command line (device checks,
training, evaluation, query client), the bundled car, bike and person models
(trained on KITTI: CC BY-NC-SA 3.0, non-commercial) and the systemd units:
fusedetd with its socket, and fusedet-record to record the sensors into
/var/lib/fusedet-recordings instead. The units are not enabled on
installation: configure the devices in /etc/fusedet/fusedet.yaml first.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Library dependencies come from dpkg-shlibdeps; the maintainer scripts need systemd-sysusers and
# deb-systemd-helper.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# A cross build (the arm64 package, docs/packaging.md) is packed for the target's Debian
# architecture, and dpkg-shlibdeps reads the target's libraries: those of the sysroot, with their
# packages and symbols files from a dpkg database of the sysroot's packages (scripts/arm64-sysroot
# makes var/lib/dpkg-shlibdeps), set for the cpack run by cmake/deb/cross.cmake.
if(CMAKE_CROSSCOMPILING)
  set(FUSEDET_SHLIBDEPS_ADMINDIR "${CMAKE_SYSROOT}/var/lib/dpkg-shlibdeps" CACHE PATH
      "Cross builds: the dpkg database (status, info/*.list, *.shlibs, *.symbols) of the sysroot's packages, for dpkg-shlibdeps")
  execute_process(COMMAND dpkg-architecture -t${CMAKE_LIBRARY_ARCHITECTURE} -qDEB_HOST_ARCH
                  OUTPUT_VARIABLE CPACK_DEBIAN_PACKAGE_ARCHITECTURE OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET
                  RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0 OR NOT CPACK_DEBIAN_PACKAGE_ARCHITECTURE)
    message(FATAL_ERROR "dpkg-architecture knows no Debian architecture for '${CMAKE_LIBRARY_ARCHITECTURE}'")
  endif()
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS
      ${CMAKE_SYSROOT}/lib/${CMAKE_LIBRARY_ARCHITECTURE} ${CMAKE_SYSROOT}/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE})
  set(FUSEDET_DEB_HOST_ARCH ${CPACK_DEBIAN_PACKAGE_ARCHITECTURE})
  configure_file(cmake/deb/cross.cmake.in ${PROJECT_BINARY_DIR}/deb/cross.cmake @ONLY)
  set(CPACK_PROJECT_CONFIG_FILE ${PROJECT_BINARY_DIR}/deb/cross.cmake)
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "systemd | systemd-standalone-sysusers | systemd-sysusers, init-system-helpers (>= 1.54~)")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/cmake/deb/postinst ${PROJECT_SOURCE_DIR}/cmake/deb/prerm
    ${PROJECT_SOURCE_DIR}/cmake/deb/postrm ${PROJECT_SOURCE_DIR}/cmake/deb/conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
set(CPACK_STRIP_FILES TRUE)
set(CPACK_SET_DESTDIR ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)  # what CMAKE_INSTALL_PREFIX is while cpack installs (with DESTDIR)
set(CPACK_INSTALL_CMAKE_PROJECTS "${PROJECT_BINARY_DIR};fusedet;runtime;/")
include(CPack)
