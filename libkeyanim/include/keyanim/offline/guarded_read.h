// Reading an untrusted file: the guards shared by the CLI (io.cpp) and the Python module
// (read_bvh, Clip), so that both refuse alike. The first bytes decide whether to read on
// (/dev/zero or a binary file is refused after 64 KiB), and reading stops past a size limit
// (a regular file's size is checked before it is read). Failures are offline::Error: io
// (with errno), malformed (not the expected kind of file) or limit.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace keyanim::offline {

// What is read; the first bytes decide, before the rest is read. kanim_or_stop: as kanim, but a
// bad signature stops the read (at most 64 KiB read) instead of failing, for a caller whose
// loader reports the error itself (the Python module's Clip names section and offset).
enum class InputKind { bvh, kanim, kanim_or_stop, either };

// A file opened for reading (not "-": callers handle standard input), refused if it is a
// directory or a regular file larger than `max_bytes`. `limit_hint` ends the message of the
// limit ("raise it with --max-input SIZE").
struct OpenedInput {
  int fd = -1;
  bool regular = false;
  uint64_t size = 0;  // a regular file's size when opened
};
OpenedInput open_guarded(const std::string& path, uint64_t max_bytes, const std::string& limit_hint);

// The whole content of `fd` (left open), under the guards above.
std::vector<uint8_t> read_guarded(int fd, const std::string& path, InputKind kind, uint64_t max_bytes, uint64_t size_hint,
                                  const std::string& limit_hint);

// Both at once, closing the file.
std::vector<uint8_t> read_file_guarded(const std::string& path, InputKind kind, uint64_t max_bytes, const std::string& limit_hint);

}  // namespace keyanim::offline
