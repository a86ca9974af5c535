# Warnings from day one; a forgotten opcode in a switch is an error.
add_compile_options(-Wall -Wextra -Werror=switch -Wno-unused-parameter)
# CI builds with every warning an error (.ci/run); a developer's build warns.
option(FRAC_WERROR "Treat warnings as errors" OFF)
if(FRAC_WERROR)
  add_compile_options(-Werror)
endif()
if(FRAC_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
# Data races: the tiered engine's compile thread, covers on several threads (make test-tsan).
option(FRAC_TSAN "Build with the thread sanitizer" OFF)
if(FRAC_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
