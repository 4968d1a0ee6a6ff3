# Writes a text file into a C++ source as a raw string returned by boycott::driver::NAME(), so the
# program carries its own copy (used for studies/reference/zeng2021.csv).
file(READ "${IN}" text)
file(WRITE "${OUT}.tmp" "// Generated from ${IN} by embed_text.cmake; do not edit.\n#include <string>\nnamespace boycott::driver {\nconst std::string& ${NAME}() {\n  static const std::string text = R\"boycott_text(${text})boycott_text\";\n  return text;\n}\n}  // namespace boycott::driver\n")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
