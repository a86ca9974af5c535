# Warnings from day one; a forgotten opcode in a switch is an error.
add_compile_options(-Wall -Wextra -Werror=switch -Wno-unused-parameter)
if(FRAC_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()
