# cellsph_unity_sources(OUT NAME BATCH SOURCES...): SOURCES compiled BATCH to a unit (the tests; the
# library's scene readers and writers; the program's sub-commands), the units named NAME_<k>.cpp. Most of
# a test unit's compile time is the headers it shares with its neighbours (six solver and scene tests: 66 CPU-s one by
# one, 29 as one unit), so each generated unit includes BATCH of them, in the glob's (folder) order.
# CMake's own UNITY_BUILD writes absolute paths into its units, which would make every fresh clone miss
# the compiler cache; these include paths relative to the checkout (found through -I<checkout>, which
# ccache's base_dir rewrites), so a clone in another folder reuses the objects. Sources that carry their
# own compile definitions (test_paths_test.cpp: the checkout's paths) stay units of their own.
# A unit is rewritten only when its list changes; editing a test recompiles its unit (the dependency
# files track the included sources).
function(cellsph_unity_sources out name batch)
  set(units)
  set(text "")
  set(count 0)
  set(index 0)
  foreach(src IN LISTS ARGN)
    get_source_file_property(defs ${src} COMPILE_DEFINITIONS)
    if(defs)
      list(APPEND units ${src})
      continue()
    endif()
    file(RELATIVE_PATH rel ${CMAKE_CURRENT_SOURCE_DIR} ${src})
    string(APPEND text "#include \"${rel}\"\n")
    math(EXPR count "${count} + 1")
    if(count EQUAL batch)
      set(unit ${CMAKE_CURRENT_BINARY_DIR}/unity/${name}_${index}.cpp)
      file(CONFIGURE OUTPUT ${unit} CONTENT "${text}" @ONLY)
      list(APPEND units ${unit})
      math(EXPR index "${index} + 1")
      set(text "")
      set(count 0)
    endif()
  endforeach()
  if(count GREATER 0)
    set(unit ${CMAKE_CURRENT_BINARY_DIR}/unity/${name}_${index}.cpp)
    file(CONFIGURE OUTPUT ${unit} CONTENT "${text}" @ONLY)
    list(APPEND units ${unit})
  endif()
  set(${out} ${units} PARENT_SCOPE)
endfunction()
