// SPDX-License-Identifier: Apache-2.0
#pragma once
// Parsing helpers shared by the subcommands.

#include <string>
#include <vector>

namespace cellmap::cli {

/// Splits "1,2.5,-3" into numbers. @throws Error naming `what` if an item is not a finite number or the count
/// is not one of `allowed_counts`.
[[nodiscard]] std::vector<double> parse_numbers(const std::string& text, const std::string& what,
                                                const std::vector<std::size_t>& allowed_counts);

}  // namespace cellmap::cli
