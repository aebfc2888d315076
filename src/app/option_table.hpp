// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The options of validate-geometry, one row each: the one place an option's value type, range,
// help and effect on the result are written. The command line (CLI11's --help, the --resume rule)
// and the Python entry points read them from here.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace asperity {

struct OptionRow {
  std::string_view flag;     ///< "--drops" (CLI11's spelling: with a short alias, "--asperities,-N")
  std::string_view target;   ///< the scene key(s) it writes, or "run control"
  std::string_view type;     ///< the value's type in --help (COUNT, METRES, ...); "" for a flag
  std::string_view range;    ///< the values it takes, in --help and in messages; "" when the type says it
  std::string_view help;
  bool changes_result;       ///< false: it may come with --resume (changes no bit of the report)
  std::uint64_t lo = 0, hi = 0;  ///< a COUNT's limits (both inclusive)
};

/// Every option, in the order of --help.
std::span<const OptionRow> option_rows();

/// The row of `flag` ("--drops"; a short alias is not looked up). Throws std::out_of_range.
const OptionRow& option_row(std::string_view flag);

/// The long flag of a row ("--asperities" of "--asperities,-N").
std::string_view long_flag(const OptionRow& row);

/// The option's type and range as --help shows them: "COUNT in [2, 2^50]", "NAME", "".
std::string type_text(const OptionRow& row);

}  // namespace asperity
