# Writes the schema files (results_schema/NNN_*.sql, in order) into a C++ source as raw strings,
# so the binary carries its own schema and migrations.
file(GLOB files "${SCHEMA_DIR}/[0-9][0-9][0-9]_*.sql")
list(SORT files)
set(body "")
foreach(f IN LISTS files)
  file(READ "${f}" sql)
  get_filename_component(n "${f}" NAME)
  string(APPEND body "  {\"${n}\", R\"boycott_sql(${sql})boycott_sql\"},\n")
endforeach()
file(WRITE "${OUT}.tmp" "// Generated from results_schema/ by embed.cmake; do not edit.\n#include \"driver/store/schema_files.hpp\"\nnamespace boycott::driver {\nconst std::vector<SchemaFile>& schema_files() {\n  static const std::vector<SchemaFile> files = {\n${body}  };\n  return files;\n}\n}  // namespace boycott::driver\n")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
