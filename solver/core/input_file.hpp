#pragma once
// Reading a file the user names (a case or a study): only a regular file of bounded size, so that
// a FIFO cannot block the program and a link to a device (/dev/zero) cannot fill its memory.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "core/error.hpp"

namespace boycott {

/// The whole text of `path`; InputError naming the file and why when it cannot be read, is not a
/// regular file (after links), or is larger than max_bytes. `what`: "case file", "study file".
inline std::string read_input_file(const std::string& path, const char* what,
                                   std::uintmax_t max_bytes = std::uintmax_t{4} << 20) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw InputError(fmt::format("cannot read {} '{}'", what, path));
  if (!fs::is_regular_file(st))
    throw InputError(
        fmt::format("{} '{}' is not a regular file (a folder, FIFO or device): refused", what, path));
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(fmt::format("cannot read {} '{}': {}", what, path, ec.message()));
  if (size > max_bytes)
    throw InputError(fmt::format("{} '{}' is {} bytes: more than the {} a {} may have", what, path, size,
                                 max_bytes, what));
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("cannot read {} '{}'", what, path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace boycott
