# CGAL is heavy to compile: it may be included only by .cpp files under geometry/, never by a
# header (inside geometry/ or anywhere else). Run as: cmake -DROOT=<source dir> -P cgal_hygiene.cmake
if(NOT ROOT)
  message(FATAL_ERROR "pass -DROOT=<source dir>")
endif()
set(include_cgal "#[ \t]*include[ \t]*[<\"]CGAL/")
file(GLOB_RECURSE headers ${ROOT}/engine/*.h ${ROOT}/engine/*.hpp ${ROOT}/geometry/*.h
  ${ROOT}/geometry/*.hpp ${ROOT}/refine/*.h ${ROOT}/refine/*.hpp ${ROOT}/tools/*.h
  ${ROOT}/tools/*.hpp ${ROOT}/tests/*.h ${ROOT}/tests/*.hpp)
file(GLOB_RECURSE outside_sources ${ROOT}/engine/*.cpp ${ROOT}/refine/*.cpp ${ROOT}/tools/*.cpp
  ${ROOT}/tests/*.cpp)
list(LENGTH headers header_count)
if(header_count EQUAL 0)
  message(FATAL_ERROR "no header found under ${ROOT}: wrong ROOT?")
endif()
set(offenders "")
foreach(f IN LISTS headers outside_sources)
  file(STRINGS ${f} hits REGEX "${include_cgal}")
  if(hits)
    list(APPEND offenders "${f}: ${hits}")
  endif()
endforeach()
if(offenders)
  list(JOIN offenders "\n  " text)
  message(FATAL_ERROR "CGAL included outside geometry/*.cpp:\n  ${text}")
endif()
message(STATUS "checked ${header_count} headers: no CGAL include")
