# SuiteSparse CHOLMOD (Debian: libsuitesparse-dev ships no CMake config) -> viscera::cholmod
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
find_library(SUITESPARSE_CONFIG_LIBRARY suitesparseconfig REQUIRED)
add_library(viscera_cholmod INTERFACE)
add_library(viscera::cholmod ALIAS viscera_cholmod)
target_include_directories(viscera_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(viscera_cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSE_CONFIG_LIBRARY})
