#pragma once
// Whole-file writes that a reader (or a kill) never sees half done: a temporary file beside the
// target, fsync, rename. A failure is the storage's (disk full, I/O error): StorageError naming
// the file and the system's own words; the temporary is removed and the target left as it was.
#include <filesystem>
#include <initializer_list>
#include <string_view>

namespace boycott::io {

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);
/// The parts one after another as one file (a checkpoint's image and its hash footer).
void write_file_atomic(const std::filesystem::path& path, std::initializer_list<std::string_view> parts);

}  // namespace boycott::io
