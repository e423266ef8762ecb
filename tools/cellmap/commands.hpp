#pragma once
// Each subcommand of the `cellmap` tool registers itself on the app; main.cpp lists them.
// A subcommand reports failure by throwing cellmap::Error (main prints its one-line reason, exits 1).

#include <CLI/CLI.hpp>

namespace cellmap::cli {

}  // namespace cellmap::cli
