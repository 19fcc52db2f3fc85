# OpenVDB (Debian ships FindOpenVDB.cmake) -> OpenVDB::openvdb.  Authoring only.
# FindOpenVDB sets BUILD_SHARED_LIBS ON (for Boost's sake) in the calling scope, which would make
# every later add_library() of that folder shared: the setting is restored after the search.
set(_viscera_shared_libs_defined FALSE)
if(DEFINED BUILD_SHARED_LIBS)
  set(_viscera_shared_libs_defined TRUE)
  set(_viscera_shared_libs "${BUILD_SHARED_LIBS}")
endif()
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
if(_viscera_shared_libs_defined)
  set(BUILD_SHARED_LIBS "${_viscera_shared_libs}")
else()
  unset(BUILD_SHARED_LIBS)
endif()
