# OpenVDB (Debian ships FindOpenVDB.cmake) -> OpenVDB::openvdb.  Authoring only.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
