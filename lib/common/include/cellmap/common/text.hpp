// SPDX-License-Identifier: Apache-2.0
#pragma once
// Parsing of the small text formats cellmap reads (CSV pose files, comma lists on the command line), and the
// quoting of input in messages.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace cellmap {

/// `text` without leading and trailing blanks (space, tab, CR).
[[nodiscard]] std::string trim(const std::string& text);

/// Splits at `separator`; every item is trimmed; a trailing separator gives a last empty item.
[[nodiscard]] std::vector<std::string> split(const std::string& line, char separator);

/// The extension of the file name in `path`, dot included, in lower case ("a/B.PNG" → ".png"); empty if it
/// has none.
[[nodiscard]] std::string lower_extension(const std::string& path);

/// `text` safe to show as one line in a log, a JSON document or a web page, whoever wrote it: every byte
/// that is not part of valid UTF-8, every control character (C0 with newline and tab, DEL, C1), the line
/// and paragraph separators U+2028/9 and the bidirectional controls (U+061C, U+200E/F, U+202A–E, U+2066–9)
/// each become '?'; then cut to at most `max_bytes` bytes, never inside a character. The one sanitizer for
/// text from the network and for messages that quote input.
[[nodiscard]] std::string single_line(std::string_view text, std::size_t max_bytes = std::string_view::npos);

/// The whole of `text` as a finite number. @throws Error "<where>: '<text>' is not a finite number".
[[nodiscard]] double parse_finite(const std::string& text, const std::string& where);

}  // namespace cellmap
