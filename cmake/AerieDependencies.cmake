# Every dependency is a Debian 12 package (scripts/setup.sh installs them).
find_package(PkgConfig REQUIRED)
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)           # LCM 1.3.1 has no CMake package
find_program(LCM_GEN lcm-gen REQUIRED)
pkg_check_modules(HWY REQUIRED IMPORTED_TARGET libhwy)         # portable SIMD (SSE4/AVX2/NEON)
pkg_check_modules(SODIUM REQUIRED IMPORTED_TARGET libsodium)   # AEAD, KDF, SHA-256 (link sealing, MAVLink signing)

find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
# Link OpenCV by component, never ${OpenCV_LIBS} (it drags opencv_viz -> VTK, see NOTES.md).
find_package(OpenCV 4.6 REQUIRED COMPONENTS core imgproc imgcodecs videoio calib3d features2d
             video tracking aruco)                             # aruco: libopencv-contrib-dev (track/fiducial)
# AprilTag 3 (libapriltag-dev): the fiducial pose source of the landing (air/track/fiducial).
find_package(apriltag 3 QUIET CONFIG)
if(NOT TARGET apriltag::apriltag)
  message(FATAL_ERROR "AprilTag 3 not found (apriltagConfig.cmake, target apriltag::apriltag): "
                      "install the Debian package libapriltag-dev (scripts/setup.sh)")
endif()
find_package(Ceres 2.1 REQUIRED)
if(NOT AERIE_AIR_ONLY)                                          # the ground side's (map, ceopt)
  find_package(octomap REQUIRED)
  find_package(dynamicEDT3D REQUIRED)
endif()
find_package(yaml-cpp REQUIRED)
find_package(CLI11 REQUIRED)
find_package(spdlog REQUIRED)
if(NOT AERIE_AIR_ONLY)
  find_package(NLopt REQUIRED)
endif()
if(NOT AERIE_AIR_ONLY OR AERIE_BUILD_TESTS)                     # air-only: test_flc's reference only
  find_library(FUZZYLITE_LIBRARY NAMES fuzzylite REQUIRED)
  find_path(FUZZYLITE_INCLUDE_DIR fl/Headers.h REQUIRED)
endif()

if(AERIE_BUILD_VIEWER)
  # VTK 9.1 on Debian needs MPI found first (NOTES.md).
  find_package(MPI REQUIRED COMPONENTS C)
  find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel FiltersSources FiltersCore
               RenderingCore RenderingOpenGL2 RenderingFreeType RenderingAnnotation RenderingContext2D
               RenderingContextOpenGL2 InteractionStyle InteractionWidgets ChartsCore
               ViewsContext2D IOImage)
endif()

if(AERIE_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(AERIE_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
