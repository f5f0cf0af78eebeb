# Shaders ship inside the binary (the engine compiles them with glslang at run time and caches
# the SPIR-V on disk), so a built `retile` runs from anywhere. glslangValidator checks every
# entry point at build time, so a shader error breaks the build instead of the first render.

find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
set(_retile_embed_script "${CMAKE_CURRENT_LIST_DIR}/EmbedShaders.cmake")

# retile_embed_shaders(<out.cpp> ROOT <dir> FILES <relative paths...>)
function(retile_embed_shaders out_cpp)
  cmake_parse_arguments(ARG "" "ROOT" "FILES" ${ARGN})
  set(abs_files)
  foreach(f IN LISTS ARG_FILES)
    list(APPEND abs_files "${ARG_ROOT}/${f}")
  endforeach()
  add_custom_command(
    OUTPUT "${out_cpp}"
    COMMAND ${CMAKE_COMMAND} -DROOT=${ARG_ROOT} "-DFILES=${ARG_FILES}" -DOUT=${out_cpp}
            -P ${_retile_embed_script}
    DEPENDS ${abs_files} ${_retile_embed_script}
    COMMENT "Embedding shader sources"
    VERBATIM)
endfunction()

# retile_check_shaders(<target> ROOT <dir> ENTRY <entry .comp files...> DEPENDS <includes...>)
function(retile_check_shaders target)
  cmake_parse_arguments(ARG "" "ROOT" "ENTRY;DEPENDS" ${ARGN})
  set(stamps)
  foreach(f IN LISTS ARG_ENTRY)
    string(REPLACE "/" "_" stem "${f}")
    set(stamp "${CMAKE_CURRENT_BINARY_DIR}/checked/${stem}.spv")
    set(deps)
    foreach(d IN LISTS ARG_DEPENDS)
      list(APPEND deps "${ARG_ROOT}/${d}")
    endforeach()
    add_custom_command(
      OUTPUT "${stamp}"
      COMMAND ${CMAKE_COMMAND} -E make_directory "${CMAKE_CURRENT_BINARY_DIR}/checked"
      COMMAND ${GLSLANG_VALIDATOR} --quiet --target-env vulkan1.2 -I${ARG_ROOT}
              -o "${stamp}" "${ARG_ROOT}/${f}"
      DEPENDS "${ARG_ROOT}/${f}" ${deps}
      COMMENT "glslangValidator ${f}"
      VERBATIM)
    list(APPEND stamps "${stamp}")
  endforeach()
  add_custom_target(${target} ALL DEPENDS ${stamps})
endfunction()
