// SPDX-License-Identifier: GPL-3.0-or-later
// Figure markup -> PLplot text and plain text (plot_render.hpp). PLplot reads '#' as its escape
// character (#u, #d, #f..., #(nnn), #[0x..]); the only escapes emitted here are "#u", "#d" and
// "##", so text from a user (a mesh file name in a title) can change nothing but the glyphs.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "plot_render.hpp"

namespace asperity::detail {

namespace {

// PLplot keeps text in fixed buffers: 1024 code points in plcore.c's encoder, and the cairo
// driver draws nothing for 500 or more. Every emitted byte is at most one code point there.
constexpr std::size_t kMaxTextBytes = 440;

// The length of the valid UTF-8 sequence at s[i] (0: invalid or a control character).
std::size_t utf8_length(std::string_view s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  if (c < 0x20 || c == 0x7f) return 0;
  if (c < 0x80) return 1;
  std::size_t n = c >= 0xF0 && c <= 0xF4 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
  if (n == 0 || i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  if (n == 3 && c == 0xE0 && static_cast<unsigned char>(s[i + 1]) < 0xA0) return 0;  // overlong
  if (n == 3 && c == 0xED && static_cast<unsigned char>(s[i + 1]) >= 0xA0) return 0;  // surrogate
  if (n == 4 && c == 0xF0 && static_cast<unsigned char>(s[i + 1]) < 0x90) return 0;  // overlong
  if (n == 4 && c == 0xF4 && static_cast<unsigned char>(s[i + 1]) >= 0x90) return 0;  // > U+10FFFF
  return n;
}

// Walks the markup once; the sink says what each piece becomes.
struct Sink {
  virtual ~Sink() = default;
  virtual void glyph(std::string_view utf8) = 0;  // one character, drawn as itself
  virtual void open(char kind) = 0;                // '_' or '^'
  virtual void close(char kind) = 0;
};

// One character at s[i] (an escape resolved); returns the bytes consumed.
std::size_t one_glyph(std::string_view s, std::size_t i, Sink& out) {
  if (s[i] == '\\' && i + 1 < s.size()) {
    const std::size_t n = utf8_length(s, i + 1);
    out.glyph(n ? s.substr(i + 1, n) : std::string_view("?"));
    return 1 + (n ? n : 1);
  }
  const std::size_t n = utf8_length(s, i);
  out.glyph(n ? s.substr(i, n) : std::string_view("?"));
  return n ? n : 1;
}

void walk(std::string_view s, Sink& out) {
  std::vector<char> open;  // the sub/superscripts of the braces not yet closed
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    if ((c == '_' || c == '^') && i + 1 < s.size()) {
      out.open(c);
      if (s[i + 1] == '{') {
        open.push_back(c);
        i += 2;
      } else {
        i += 1 + one_glyph(s, i + 1, out);
        out.close(c);
      }
    } else if (c == '}' && !open.empty()) {
      out.close(open.back());
      open.pop_back();
      ++i;
    } else {
      i += one_glyph(s, i, out);
    }
  }
  while (!open.empty()) {
    out.close(open.back());
    open.pop_back();
  }
}

struct PlplotSink : Sink {
  std::string text;
  std::vector<char> levels;  // what is open, to close it when the text is cut
  std::size_t ignored = 0;   // sub/superscripts opened after the cut
  bool full = false;
  bool fits(std::size_t bytes) {
    // Room for the bytes, the closing escapes of every open level and an ellipsis.
    if (!full && text.size() + bytes + 2 * levels.size() + 5 > kMaxTextBytes) {
      full = true;
      text += "\xE2\x80\xA6";
    }
    return !full;
  }
  void glyph(std::string_view g) override {
    if (!fits(g == "#" ? 2 : g.size())) return;
    text += g == "#" ? std::string_view("##") : g;
  }
  void open(char kind) override {
    if (!fits(2)) {
      ++ignored;
      return;
    }
    text += kind == '_' ? "#d" : "#u";
    levels.push_back(kind);
  }
  void close(char kind) override {
    if (ignored > 0) {
      --ignored;
      return;
    }
    text += kind == '_' ? "#u" : "#d";
    levels.pop_back();
  }
};

struct PlainSink : Sink {
  std::string text;
  void glyph(std::string_view g) override { text += g; }
  void open(char kind) override { text += kind; }
  void close(char) override {}
};

}  // namespace

std::string plplot_text(std::string_view markup) {
  PlplotSink s;
  walk(markup, s);  // walk closes every level it opened
  return s.text;
}

std::string plain_text(std::string_view markup) {
  PlainSink s;
  walk(markup, s);
  return s.text;
}

}  // namespace asperity::detail
