// Files to remove if the process is stopped by SIGINT, SIGTERM or SIGHUP
// (then re-raised with the default action, so the exit status still says
// which signal). Used for the few named temporaries that cannot be avoided
// (output_file.hpp's fallback, the JIT's build directory). Registration is
// async-signal-safe to read from the handler: a fixed table of paths.
#pragma once

#include <string>

namespace kanegen {

/// Registers `path` (a file or a directory, removed recursively) for removal
/// on a fatal signal; returns a slot to pass to unregister_cleanup().
int register_cleanup(const std::string& path);
void unregister_cleanup(int slot);

}  // namespace kanegen
