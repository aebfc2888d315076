// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Names (files, scenes, keys) entering text that someone else reads: a terminal, a PLY header, a
// TOML or JSON file (issue 33). A POSIX name may hold any byte but '/' and NUL; each format can
// hold fewer. Escaped here for the formats that can show any byte (messages, PLY comments), and
// checked for the ones that cannot hold a byte that is not UTF-8 (JSON, TOML): such a name is
// refused up front (utf8_problem), before the run, instead of failing when the report is written.
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace asperity::detail {

/// The length of the UTF-8 sequence at s[i] and its code point (0 length: not valid UTF-8 there:
/// a stray continuation byte, a truncated or overlong sequence, a surrogate, beyond U+10FFFF).
inline std::size_t utf8_at(std::string_view s, std::size_t i, std::uint32_t& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  cp = n == 1 ? c : n == 2 ? (c & 0x1fu) : n == 3 ? (c & 0x0fu) : (c & 0x07u);
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xc0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3fu);
  }
  const std::uint32_t min[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < min[n] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  return n;
}

/// "" if `s` is valid UTF-8; else where it is not ("byte 4 (0xff) is not UTF-8").
inline std::string utf8_problem(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    std::uint32_t cp = 0;
    const std::size_t n = utf8_at(s, i, cp);
    if (n == 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "byte %zu (0x%02x) is not UTF-8", i + 1, static_cast<unsigned>(static_cast<unsigned char>(s[i])));
      return buf;
    }
    i += n;
  }
  return "";
}

/// `s` for a terminal or a one-line header: every control character (C0, DEL, and the C1 controls
/// U+0080..U+009F that some terminals obey as escape sequences) and every byte that is not UTF-8
/// shown as \xNN; a backslash as "\\" when `backslash` (then the text maps back to the bytes);
/// non-ASCII as \xNN bytes too when `ascii` (a PLY header is ASCII).
inline std::string escaped(std::string_view s, bool backslash = false, bool ascii = false) {
  std::string out;
  const auto hex = [&](unsigned char u) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02x", u);
    out += buf;
  };
  for (std::size_t i = 0; i < s.size();) {
    const auto u = static_cast<unsigned char>(s[i]);
    std::uint32_t cp = 0;
    const std::size_t n = utf8_at(s, i, cp);
    if (n == 0 || cp < 0x20 || cp == 0x7f || (cp >= 0x80 && cp <= 0x9f) || (ascii && cp >= 0x80)) {
      for (std::size_t k = 0; k < (n == 0 ? 1 : n); ++k) hex(static_cast<unsigned char>(s[i + k]));
      i += n == 0 ? 1 : n;
      continue;
    }
    if (backslash && u == '\\') out += '\\';
    out.append(s.substr(i, n));
    i += n;
  }
  return out;
}

}  // namespace asperity::detail
