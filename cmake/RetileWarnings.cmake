# One place for the warning set, so the engine, the app and the tests are held to the same bar.
function(retile_set_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
    -Wnull-dereference -Wimplicit-fallthrough -Wformat=2 -Wmissing-declarations
    # Vulkan create-info structs are set up as `VkFoo info{VK_STRUCTURE_TYPE_FOO}` then filled in.
    -Wno-missing-field-initializers)
  if(RETILE_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
