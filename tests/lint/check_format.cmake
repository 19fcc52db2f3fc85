# The tree is formatted with the root .clang-format: `clang-format --dry-run -Werror` over every
# C++ source and header of core, studio, player, tests and bench must report no deviation.
# Usage: cmake -DSOURCE_DIR=<repo> -DCLANG_FORMAT=<clang-format> -P check_format.cmake
if(NOT CLANG_FORMAT OR NOT EXISTS "${CLANG_FORMAT}")
  message(FATAL_ERROR "clang-format not found: install Debian's clang-format (scripts/install-deps.sh)")
endif()
file(GLOB_RECURSE files "${SOURCE_DIR}/core/*.[ch]pp" "${SOURCE_DIR}/studio/*.[ch]pp" "${SOURCE_DIR}/player/*.[ch]pp" "${SOURCE_DIR}/launcher/*.[ch]pp"
     "${SOURCE_DIR}/tests/*.[ch]pp" "${SOURCE_DIR}/bench/*.[ch]pp")
list(LENGTH files count)
execute_process(COMMAND "${CLANG_FORMAT}" --style=file --dry-run -Werror ${files}
                WORKING_DIRECTORY "${SOURCE_DIR}" RESULT_VARIABLE rc ERROR_VARIABLE out OUTPUT_VARIABLE out2)
if(NOT rc EQUAL 0)
  string(REGEX MATCHALL "[^\n]*error: code should be clang-formatted[^\n]*" hits "${out}")
  list(LENGTH hits n)
  list(SUBLIST hits 0 20 first)
  string(REPLACE ";" "\n" first "${first}")
  message(FATAL_ERROR "${n} formatting deviation(s) in ${count} files (fix: clang-format -i <file>):\n${first}")
endif()
message(STATUS "clang-format: 0 deviations in ${count} files")
