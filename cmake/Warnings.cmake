# Warnings as errors on the project's own targets (never on third-party headers, included as SYSTEM).
function(hapticd_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Werror)
endfunction()
