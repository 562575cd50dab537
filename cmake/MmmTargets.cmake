# Helpers that give every mmm target the same compile settings:
# warnings as errors on our code, third-party headers as SYSTEM (imported
# targets), optional sanitizers.

function(mmm_target_settings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
    -Wcast-align -Woverloaded-virtual -Wimplicit-fallthrough
    -Werror)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    # GCC 12 at -O3 reports std::string copies inside libstdc++ as
    # overlapping (GCC bugs 105329, 105651): a false positive in system
    # headers that -Werror would turn into a build failure.
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(MMM_SANITIZE)
    # Sanitizer instrumentation makes GCC's -Wmaybe-uninitialized misfire in
    # inlined third-party code (OpenMesh's PropertyT::push_back(T()) with an
    # intentionally uninitialised VectorT); the plain build keeps the warning.
    target_compile_options(${target} PRIVATE -fsanitize=${MMM_SANITIZE} -fno-omit-frame-pointer
                                             -fno-sanitize-recover=all -Wno-maybe-uninitialized)
    target_link_options(${target} PRIVATE -fsanitize=${MMM_SANITIZE})
  endif()
endfunction()

# mmm_add_library(<name> ALIAS <ns::name> [DEPS <targets>...]
#                 [SOURCES <files>...] [EXCLUDE <files>...])
# One static library per top-level folder; sources are the .cpp files below
# the calling folder (one algorithm per name.h/name.cpp pair), or exactly
# SOURCES when given; EXCLUDE removes files another library of the folder owns.
function(mmm_add_library name)
  cmake_parse_arguments(ARG "" "ALIAS" "DEPS;SOURCES;EXCLUDE" ${ARGN})
  if(ARG_SOURCES)
    list(TRANSFORM ARG_SOURCES PREPEND ${CMAKE_CURRENT_SOURCE_DIR}/ OUTPUT_VARIABLE sources)
  else()
    file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  endif()
  foreach(excluded ${ARG_EXCLUDE})
    list(REMOVE_ITEM sources ${CMAKE_CURRENT_SOURCE_DIR}/${excluded})
  endforeach()
  if(NOT sources)
    # A folder whose layer has no code yet is still a target, so that the
    # dependency direction (nodes -> workflow -> core) is fixed from the start.
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} INTERFACE ${ARG_DEPS})
    add_library(${ARG_ALIAS} ALIAS ${name})
    return()
  endif()
  add_library(${name} STATIC ${sources})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  mmm_target_settings(${name})
  if(MMM_SANITIZE)
    target_link_options(${name} INTERFACE -fsanitize=${MMM_SANITIZE})
  endif()
  add_library(${ARG_ALIAS} ALIAS ${name})
endfunction()
