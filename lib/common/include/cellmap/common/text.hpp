// SPDX-License-Identifier: Apache-2.0
#pragma once
// Parsing of the small text formats cellmap reads (CSV pose files, comma lists on the command line), and the
// quoting of input in messages.

#include <string>
#include <vector>

namespace cellmap {

/// `text` without leading and trailing blanks (space, tab, CR).
[[nodiscard]] std::string trim(const std::string& text);

/// Splits at `separator`; every item is trimmed; a trailing separator gives a last empty item.
[[nodiscard]] std::vector<std::string> split(const std::string& line, char separator);

/// The extension of the file name in `path`, dot included, in lower case ("a/B.PNG" → ".png"); empty if it
/// has none.
[[nodiscard]] std::string lower_extension(const std::string& path);

/// `text` with every control character (newline included) replaced by '?': for messages that quote input,
/// which must stay one line.
[[nodiscard]] std::string single_line(std::string text);

/// The whole of `text` as a finite number. @throws Error "<where>: '<text>' is not a finite number".
[[nodiscard]] double parse_finite(const std::string& text, const std::string& where);

}  // namespace cellmap
