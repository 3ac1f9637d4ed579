# SPDX-License-Identifier: Apache-2.0
# Installs the build tree into PREFIX and checks the files a robot integrator relies on.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
foreach(f bin/fusedet bin/fusedetd etc/fusedet/fusedet.yaml lib/systemd/system/fusedetd.service
          lib/systemd/system/fusedetd.socket include/fusedet/core/layer_stack.h
          include/fusedet/core/detection.h include/fusedet/drivers/messages.h)
  if(NOT EXISTS ${PREFIX}/${f})
    message(FATAL_ERROR "missing after install: ${f}")
  endif()
endforeach()
file(READ ${PREFIX}/lib/systemd/system/fusedetd.service unit)
if(NOT unit MATCHES "Type=notify" OR NOT unit MATCHES "ExecStart=/")
  message(FATAL_ERROR "fusedetd.service lacks Type=notify or an absolute ExecStart")
endif()
message(STATUS "install tree complete under ${PREFIX}")
