// Which existing outputs are written in place rather than replaced: shared by the CLI (io.cpp)
// and the Python module (Motion.write_bvh), so that both keep the same rule. Renaming a
// temporary file over a device, a FIFO or a link to one would replace the node (as root,
// /dev/null) and send nothing where the user meant; a link to this process's own standard
// output or error (/dev/stdout -> /proc/self/fd/1) would be replaced too, leaving empty the file
// the shell opened.
#pragma once
#include <string>

namespace keyanim::offline {

// -1 when `path` is absent or a regular file (or a link to one that is not a standard stream
// of this process): write a temporary file beside it and rename it. Otherwise a descriptor
// open for writing to it (the caller closes it); on failure -2 with errno set. A FIFO's open
// waits for its reader, as with every program writing to one.
int open_in_place(const std::string& path);

}  // namespace keyanim::offline
