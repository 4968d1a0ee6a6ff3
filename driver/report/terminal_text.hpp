#pragma once
// Text from the user (file names, values, names) printed in a message: its control characters
// shown as \xNN, so that an escape sequence in a file name or a value cannot move the cursor,
// recolour or retitle the user's terminal. UTF-8 text (⟨w_p⟩, θ) passes unchanged.
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace boycott::driver {

inline std::string printable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const auto next = i + 1 < s.size() ? static_cast<unsigned char>(s[i + 1]) : 0u;
    if (c < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02X}", c);
    } else if (c == 0xC2 && next >= 0x80 && next <= 0x9F) {
      // U+0080..U+009F, the C1 controls (CSI among them), in UTF-8.
      out += fmt::format("\\u{:04X}", next);
      ++i;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace boycott::driver
