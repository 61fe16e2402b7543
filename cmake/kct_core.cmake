# The ROS-free core library, shared by the catkin build (CMakeLists.txt) and the plain-CMake
# core-only build (cmake/core_only.cmake). Expects OpenCV, Eigen3, NLopt, assimp and
# meshoptimizer found.
# It links only those and never sees catkin's include directories, so an #include <ros/...> in
# it fails to compile (and the core-only build has no catkin at all).
file(GLOB KCT_CORE_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/core/*.cpp)
add_library(klt_contour_tracker_core ${KCT_CORE_SOURCES})
target_include_directories(klt_contour_tracker_core PUBLIC
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>)
target_include_directories(klt_contour_tracker_core SYSTEM PUBLIC
  ${OpenCV_INCLUDE_DIRS} ${EIGEN3_INCLUDE_DIRS})
target_link_libraries(klt_contour_tracker_core PUBLIC ${OpenCV_LIBS} PRIVATE NLopt::nlopt assimp::assimp
  meshoptimizer::meshoptimizer)
set_target_properties(klt_contour_tracker_core PROPERTIES POSITION_INDEPENDENT_CODE ON)
