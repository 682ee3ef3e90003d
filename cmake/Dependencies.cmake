# Every dependency comes from Debian 12's packages (see scripts/setup).

find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs features2d flann highgui)
find_package(assimp REQUIRED)
find_package(PCL 1.12 REQUIRED COMPONENTS common io)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(MATIO REQUIRED IMPORTED_TARGET matio)
pkg_check_modules(ZLIB REQUIRED IMPORTED_TARGET zlib)
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
# FLANN's C++ API is header-only; its serialisation needs lz4 linked explicitly.
find_path(FLANN_INCLUDE_DIR flann/flann.hpp REQUIRED)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
# OpenNI2 (Debian's libopenni2-dev): RGB-D cameras and .oni recordings, used by camera/ only.
pkg_check_modules(OPENNI2 REQUIRED IMPORTED_TARGET libopenni2)
