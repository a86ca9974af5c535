// Cleaning up after a process however it ends, SIGKILL included, when no destructor or exit handler
// runs: a cleaner process (sh) waits for the end of its input, a pipe or socket that only the process
// (and whoever it hands the descriptor to) holds, then removes what it was told to.
#pragma once

#include <string>
#include <sys/types.h>
#include <vector>

namespace frac::support {

// Starts `/bin/sh -c SCRIPT NAME ARGS...` with `input` as its standard input, its output discarded and no
// other descriptor of this process, ignoring the terminal's signals. Returns its pid, or -1.
pid_t spawn_cleaner(int input, const std::string& script, const std::string& name,
                    const std::vector<std::string>& args);

// Has `path` removed, if it still exists, once this process has ended however it ends: a cleaner
// started on first use (one per process; a forked child starts its own) is told the name and removes it
// when the process is gone. A relative path is taken from the current directory. For names that must
// never outlive their writer, as AtomicFile's temporaries.
void remove_when_process_ends(const std::string& path);

} // namespace frac::support
