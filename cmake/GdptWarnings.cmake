# gdpt_warnings: INTERFACE target carrying the project's warning flags (-Werror with GDPT_WERROR).
add_library(gdpt_warnings INTERFACE)
target_compile_options(gdpt_warnings INTERFACE -Wall -Wextra -Wshadow -Wconversion
                       -Wno-sign-conversion -Wno-missing-field-initializers $<$<BOOL:${GDPT_WERROR}>:-Werror>)
