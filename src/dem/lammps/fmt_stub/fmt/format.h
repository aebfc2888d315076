/* SPDX-License-Identifier: MIT */
/* Copyright (c) 2026 the asperity developers. MIT (LICENSE's text). */
// Debian's liblammps-dev (20220106) headers include "fmt/format.h", but LAMMPS's fmt is bundled
// inside liblammps (namespace fmt::v7_lmp) and its headers are not shipped. These declarations are
// just enough to compile the LAMMPS headers: the fmt-formatting overloads (Error::all(file, line,
// format, args...), utils::logmesg with arguments) cannot be instantiated with them, so the coupling
// can only call the plain std::string overloads, which need no fmt at all.
#pragma once
namespace fmt {
inline namespace v7_lmp {
template <typename Char> class basic_string_view;
using string_view = basic_string_view<char>;
class format_args;
template <typename... Args, typename S> void make_args_checked(const S&, const Args&...) = delete;
}  // namespace v7_lmp
}  // namespace fmt
