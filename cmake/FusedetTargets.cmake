# SPDX-License-Identifier: Apache-2.0
# Helpers shared by every folder: one place for warnings, test and benchmark registration.

# Warnings for our own targets (never for third-party headers).
function(fusedet_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wcast-align -Wnull-dereference -Wformat=2)
  # Not in sanitizer builds: GCC's flow-sensitive warnings (null-dereference, mismatched-new-delete,
  # maybe-uninitialized) change with the instrumentation and -O1 and were false there, in libstdc++,
  # CLI11 and our tests alike (docs/reliability.md); the plain build keeps every warning an error.
  if(FUSEDET_WERROR AND NOT FUSEDET_SANITIZE)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# fusedet_library(<name> SOURCES ... DEPS ...): a static library with public headers in include/.
function(fusedet_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                            $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  fusedet_warnings(${name})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
  install(TARGETS ${name} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
endfunction()

# fusedet_test(<name> SOURCES ... DEPS ... [LABELS ...]): a GoogleTest binary, each TEST a ctest case.
# Tests find the KITTI data through FUSEDET_DATA_DIR (default: ../shared/data beside the checkout).
function(fusedet_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE
    FUSEDET_DATA_DIR="${FUSEDET_DATA_DIR}" FUSEDET_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    FUSEDET_BINARY_DIR="${PROJECT_BINARY_DIR}")
  fusedet_warnings(${name})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
                       PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}")
endfunction()

# fusedet_bench(<name> SOURCES ... DEPS ... [SMOKE_ARGS ...]): a benchmark program plus a ctest case
# that runs it once with SMOKE_ARGS (default: one short Google Benchmark pass) so it cannot rot.
function(fusedet_bench name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;SMOKE_ARGS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} benchmark::benchmark)
  target_compile_definitions(${name} PRIVATE FUSEDET_DATA_DIR="${FUSEDET_DATA_DIR}")
  fusedet_warnings(${name})
  if(NOT ARG_SMOKE_ARGS)
    set(ARG_SMOKE_ARGS --benchmark_min_time=0)
  endif()
  if(FUSEDET_BUILD_TESTS)
    add_test(NAME bench_smoke.${name} COMMAND ${name} ${ARG_SMOKE_ARGS})
    set_tests_properties(bench_smoke.${name} PROPERTIES LABELS bench TIMEOUT 600)
  endif()
endfunction()

get_filename_component(_default_data "${PROJECT_SOURCE_DIR}/../shared/data" ABSOLUTE)
set(FUSEDET_DATA_DIR "${_default_data}" CACHE PATH "Root of the shared KITTI data (kitti/, kitti_0009/, ...)")
get_filename_component(_default_networks "${PROJECT_SOURCE_DIR}/../shared/models" ABSOLUTE)
set(FUSEDET_NETWORKS_DIR "${_default_networks}" CACHE PATH
    "Pretrained COCO detector files (Yolo-Fastest-XL, YOLOv5n: read at run time, never copied into the repository)")
