# Warning flags for every sunvo target; errors in CI (SUNVO_WERROR=ON).
add_library(sunvo_warnings INTERFACE)
target_compile_options(sunvo_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
  -Wunused -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2
  -Wimplicit-fallthrough
  $<$<BOOL:${SUNVO_WERROR}>:-Werror>)
if(SUNVO_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
if(SUNVO_SANITIZE_THREAD)
  if(SUNVO_SANITIZE)
    message(FATAL_ERROR "SUNVO_SANITIZE_THREAD and SUNVO_SANITIZE exclude each other")
  endif()
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
if(SUNVO_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "SUNVO_FUZZ needs clang (libFuzzer): use the fuzz preset")
  endif()
  # Coverage for libFuzzer in every object; the harnesses add -fsanitize=fuzzer (its main).
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                      -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()

# sunvo_library(<name> SOURCES ... DEPS ...): one library target for one folder.
function(sunvo_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE sunvo_warnings ${ARG_PRIVATE_DEPS})
endfunction()

# sunvo_executable(<name> SOURCES ... DEPS ...): a program. Every program lands in <build>/bin,
# whichever folder its sources live in, so scripts and tests name it by its program name alone.
function(sunvo_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
  target_link_libraries(${name} PRIVATE sunvo_warnings ${ARG_DEPS})
endfunction()
