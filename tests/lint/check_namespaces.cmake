# One library, one namespace (README "Layout"): every namespace a source file opens must be the
# namespace of its library, or that namespace's `detail` (internals), or `render::gl` (the GL
# backend behind render::Backend). Files of the command-line programs open none but an anonymous one.
# Usage: cmake -DSOURCE_DIR=<repo> -P check_namespaces.cmake   (fails listing every offending line)
cmake_policy(SET CMP0007 NEW)
set(rules
  "core/sim/=viscera::sim"
  "core/case/=viscera::vcase"
  "core/haptics/=viscera::haptics"
  "core/render/gl/=viscera::render::gl|viscera::render"
  "core/render/=viscera::render"
  "studio/bake/=viscera::bake"
  "studio/project/=viscera::studio"
  "studio/app/=viscera::studio"
  "player/runtime/=viscera::player"
  "player/window/=viscera::player"
  "player/plots/=viscera::player"
  "player/results/main.cpp="
  "player/results/=viscera::player"
  "launcher/main.cpp="
  "launcher/=viscera::launcher"
  "studio/cli/="
  "player/console_sim/="
  "player/main.cpp=")
# A header may open another library's namespace (forward declarations of its types); a nested
# `namespace detail {` is allowed anywhere; core/sim/util holds the shared error and log types
# (namespace viscera, viscera::log).
set(libraries "viscera::sim" "viscera::vcase" "viscera::haptics" "viscera::render" "viscera::bake" "viscera::studio"
    "viscera::player" "viscera::launcher")
set(shared "viscera" "viscera::log")

file(GLOB_RECURSE files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/core/*.[ch]pp" "${SOURCE_DIR}/studio/*.[ch]pp"
     "${SOURCE_DIR}/player/*.[ch]pp" "${SOURCE_DIR}/launcher/*.[ch]pp")
set(problems "")
set(count 0)
foreach(f IN LISTS files)
  set(expected "-")
  foreach(rule IN LISTS rules)
    string(REPLACE "=" ";" pair "${rule}")
    list(GET pair 0 prefix)
    list(LENGTH pair n)
    set(ns "")
    if(n GREATER 1)
      list(GET pair 1 ns)
    endif()
    string(FIND "${f}" "${prefix}" at)
    if(at EQUAL 0 AND expected STREQUAL "-")
      set(expected "${ns}")
    endif()
  endforeach()
  if(expected STREQUAL "-")
    string(APPEND problems "\n  ${f}: no namespace rule for this folder")
    continue()
  endif()
  math(EXPR count "${count} + 1")
  file(STRINGS "${SOURCE_DIR}/${f}" lines REGEX "^namespace [A-Za-z_:]+ *{")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^namespace ([A-Za-z_:]+).*" "\\1" ns "${line}")
    set(ok FALSE)
    string(REPLACE "|" ";" allowed "${expected}")
    foreach(a IN LISTS allowed)
      if(ns STREQUAL a OR ns STREQUAL "${a}::detail" OR ns STREQUAL "detail")
        set(ok TRUE)
      endif()
    endforeach()
    list(FIND shared "${ns}" sharedAt)
    if(sharedAt GREATER -1 AND f MATCHES "^core/sim/util/")
      set(ok TRUE)
    endif()
    list(FIND libraries "${ns}" libraryAt)
    if(libraryAt GREATER -1 AND f MATCHES "\\.hpp$")
      set(ok TRUE)
    endif()
    if(NOT ok)
      string(REPLACE "|" " or " expected "${expected}")
      if(expected STREQUAL "")
        set(expected "none (an anonymous namespace only)")
      endif()
      string(APPEND problems "\n  ${f}: opens namespace ${ns}; its folder's namespace is ${expected}")
    endif()
  endforeach()
endforeach()
if(problems)
  message(FATAL_ERROR "namespace rule broken:${problems}")
endif()
message(STATUS "namespace rule holds in ${count} files")
