// Banks on the command line (spec/FORMAT.md section 10): opening one, with the tool's exit codes
// and messages, and LIB:NAME, the name of one clip of a bank wherever a .kanim file is read.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "keyanim/bank.h"

namespace keyanim::cli {

// Whether `bytes` start as a bank's header does (the .kanim signature, Header_Flags bit 2).
bool looks_like_bank(const std::vector<uint8_t>& bytes);

// Opens a bank read from `path` (its index checked; exit 2, 3 or 6 as a .kanim's load).
Bank open_bank(const std::string& path, const std::vector<uint8_t>& bytes);

// Clip i of `bank` (read from `path`), loaded as load_kanim loads a file: exit 2 naming the clip
// if it is damaged.
Clip load_bank_clip(const std::string& path, const Bank& bank, uint32_t i, const Globals& g);

// LIB:NAME: when `path` names no file but ends in ":NAME" after the path of a file, that file
// and NAME (split at the last ':' that leaves an existing file before it).
struct MemberPath {
  std::string bank;
  std::string name;
};
std::optional<MemberPath> member_path(const std::string& path);

// The clip NAME of the bank `bytes` (read from the path LIB:NAME) as a file of its own, in the
// bank's profile: what `keyanim unpack` writes for it. Exit 2 if there is no such clip.
std::vector<uint8_t> member_file(const MemberPath& m, const std::vector<uint8_t>& bytes, const Globals& g);

// A clip as a file of its own: the runtime profile's bytes, or the archive's.
std::vector<uint8_t> clip_file(const Clip& clip, bool runtime);

}  // namespace keyanim::cli
