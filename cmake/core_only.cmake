# Plain-CMake build of the ROS-free core, its gtests and track_sequence, with no catkin at all
# (cmake -DKCT_CORE_ONLY=ON <repo>): proves the core embeds without ROS, and is the build the
# guards of scripts/test.sh use:
#   -DKCT_SANITIZE=ON  AddressSanitizer + UndefinedBehaviorSanitizer (any UB report fails)
#   -DKCT_FUZZ=ON      libFuzzer targets test/fuzz/fuzz_<name>.cpp (clang), each registered as a
#                      ctest test running KCT_FUZZ_RUNS inputs (at most KCT_FUZZ_SECONDS) from
#                      its committed seed corpus
#                      test/fuzz/corpus/<name>/, plus one test replaying the crash inputs of
#                      test/fuzz/regressions/<name>/.
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d video features2d)
find_package(Eigen3 REQUIRED)
find_package(NLopt REQUIRED)
find_package(assimp REQUIRED)
find_package(meshoptimizer REQUIRED)

option(KCT_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(KCT_FUZZ "Build the libFuzzer targets (clang)" OFF)
set(KCT_FUZZ_SECONDS 20 CACHE STRING "Upper bound of the seconds each fuzz target runs under ctest")
set(KCT_FUZZ_RUNS 1000000 CACHE STRING "At most this many inputs per fuzz target under ctest (seed 1)")
set(KCT_FUZZ_MESH_RUNS 300 CACHE STRING "At most this many inputs for the mesh loading target")
if(KCT_SANITIZE)
  set(KCT_SANITIZER_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all
      -fno-omit-frame-pointer -g)
  add_compile_options(${KCT_SANITIZER_FLAGS} -O1)
  add_link_options(${KCT_SANITIZER_FLAGS})
endif()

include(${CMAKE_CURRENT_LIST_DIR}/kct_core.cmake)

add_executable(track_sequence ${PROJECT_SOURCE_DIR}/src/tools/track_sequence.cpp)
target_link_libraries(track_sequence klt_contour_tracker_core)

enable_testing()
option(KCT_CORE_TESTS "Build the core gtests (off for a fuzz-only build)" ON)
if(KCT_CORE_TESTS)
  find_package(GTest REQUIRED)
  file(GLOB KCT_CORE_TESTS_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/core/test_*.cpp)
endif()
# Sanitized tests run through cmake/lsan_tracer_retry.sh: run once more only when LeakSanitizer's
# own tracer crashed at exit after everything passed (a sanitizer-runtime flake; see the script).
set(KCT_TEST_LAUNCHER "")
if(KCT_SANITIZE)
  set(KCT_TEST_LAUNCHER bash ${PROJECT_SOURCE_DIR}/cmake/lsan_tracer_retry.sh)
  if(KCT_CORE_TESTS)  # once (the fuzz-only build is sanitized too)
    add_test(NAME core_only_lsan_tracer_retry
             COMMAND bash ${PROJECT_SOURCE_DIR}/test/ci/test_lsan_tracer_retry.sh)
  endif()
endif()
foreach(test_source ${KCT_CORE_TESTS_SOURCES})
  get_filename_component(test_name ${test_source} NAME_WE)
  add_executable(${test_name} ${test_source})
  target_link_libraries(${test_name} klt_contour_tracker_core GTest::gtest_main GTest::gtest)
  target_compile_definitions(${test_name} PRIVATE KCT_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_test(NAME core_only_${test_name} COMMAND ${KCT_TEST_LAUNCHER} $<TARGET_FILE:${test_name}>
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endforeach()

# A short track_sequence run (under the sanitizers when KCT_SANITIZE) on a rendered sequence
# folder, e.g. the rostests' (devel/share/klt_contour_tracker/test_data/small).
set(KCT_SEQUENCE_DIR "" CACHE PATH "Sequence folder for the track_sequence test ('' = no test)")
if(KCT_SEQUENCE_DIR)
  add_test(NAME core_only_track_sequence
           COMMAND ${KCT_TEST_LAUNCHER} $<TARGET_FILE:track_sequence> --sequence ${KCT_SEQUENCE_DIR}
                   --model ${PROJECT_SOURCE_DIR}/models/demo_crate.obj --max-frames 6
                   --param visibility_cache_dir= --param icosphere_subdivisions=2
                   --summary-json ${CMAKE_CURRENT_BINARY_DIR}/track_sequence_summary.json)
endif()

if(KCT_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "KCT_FUZZ needs clang (CXX=clang++): libFuzzer is part of clang")
  endif()
  # The image/camera_info conversion lives in the ROS layer: its fuzz target compiles that one
  # file against the ROS message headers and libraries in /usr (no catkin needed).
  find_library(KCT_CV_BRIDGE cv_bridge)
  find_library(KCT_IMAGE_GEOMETRY image_geometry)
  find_library(KCT_ROSCPP_SERIALIZATION roscpp_serialization)
  find_library(KCT_ROSTIME rostime)
  find_library(KCT_CPP_COMMON cpp_common)
  file(GLOB KCT_FUZZ_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/test/fuzz/fuzz_*.cpp)
  foreach(fuzz_source ${KCT_FUZZ_SOURCES})
    get_filename_component(fuzz_name ${fuzz_source} NAME_WE)
    string(REGEX REPLACE "^fuzz_" "" corpus_name ${fuzz_name})
    add_executable(${fuzz_name} ${fuzz_source})
    target_compile_options(${fuzz_name} PRIVATE -fsanitize=fuzzer)
    target_link_options(${fuzz_name} PRIVATE -fsanitize=fuzzer)
    target_link_libraries(${fuzz_name} klt_contour_tracker_core)
    if(fuzz_name STREQUAL "fuzz_image_conversion")
      target_sources(${fuzz_name} PRIVATE ${PROJECT_SOURCE_DIR}/src/ros/camera_conversion.cpp)
      target_link_libraries(${fuzz_name} ${KCT_CV_BRIDGE} ${KCT_IMAGE_GEOMETRY}
                            ${KCT_ROSCPP_SERIALIZATION} ${KCT_ROSTIME} ${KCT_CPP_COMMON})
    endif()
    set(corpus ${PROJECT_SOURCE_DIR}/test/fuzz/corpus/${corpus_name})
    set(found ${CMAKE_CURRENT_BINARY_DIR}/fuzz_found/${corpus_name})
    file(MAKE_DIRECTORY ${found})
    # New inputs go to a build folder (first corpus argument); the committed seeds stay as they
    # are. A fixed seed and run count make the run reproducible; KCT_FUZZ_SECONDS bounds it on a
    # slow machine. A crash, sanitizer report, leak, timeout (> 10 s per input) or > 2 GB RSS
    # fails the test.
    # Mesh loading runs ~10 inputs/s (assimp): a fixed count keeps it deterministic.
    set(runs ${KCT_FUZZ_RUNS})
    if(corpus_name STREQUAL "mesh_loading")
      set(runs ${KCT_FUZZ_MESH_RUNS})
    endif()
    add_test(NAME fuzz_${corpus_name}
             COMMAND ${KCT_TEST_LAUNCHER} $<TARGET_FILE:${fuzz_name}> -seed=1 -runs=${runs}
                     -max_total_time=${KCT_FUZZ_SECONDS} -timeout=10 -rss_limit_mb=2048
                     -max_len=65536 -print_final_stats=1 ${found} ${corpus})
    file(GLOB regressions ${PROJECT_SOURCE_DIR}/test/fuzz/regressions/${corpus_name}/*)
    if(regressions)
      add_test(NAME fuzz_${corpus_name}_regressions
               COMMAND ${KCT_TEST_LAUNCHER} $<TARGET_FILE:${fuzz_name}> -rss_limit_mb=2048 ${regressions})
    endif()
  endforeach()
endif()
