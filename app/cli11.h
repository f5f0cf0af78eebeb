// CLI11 (Debian's libcli11-dev, header-only), for the command line's files. Main thread only.
#pragma once

// GCC 12 at -O2 reports a "potential null pointer dereference" inside libstdc++'s std::string,
// inlined into CLI11's CLI::detail::split: a false positive in code that is not ours, which
// -Werror would turn into a failed build. Silenced for CLI11 alone; the rest keeps the warning.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <CLI/CLI.hpp>
#pragma GCC diagnostic pop
