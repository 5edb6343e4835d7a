#include "bank_io.h"

#include <sys/stat.h>

#include "keyanim/offline/container.h"
#include "keyanim/offline/error.h"

namespace keyanim::cli {

bool looks_like_bank(const std::vector<uint8_t>& bytes) {
  // Header_Flags (a little-endian u32 at offset 12) bit 2: spec section 10.2.
  return looks_like_kanim(bytes) && bytes.size() >= 16 && (bytes[12] & 0x04) != 0;
}

namespace {

int exit_code_of(Status s) {
  return s == Status::unsupported_version ? kUnsupported : s == Status::limit_exceeded ? kLimit : kBadInput;
}

DecodeLimits tool_limits(const Globals& g) {
  DecodeLimits limits;  // as load_kanim's
  limits.max_keys = std::min(limits.max_keys, g.limits.max_values);
  limits.check_content = true;
  return limits;
}

}  // namespace

Bank open_bank(const std::string& path, const std::vector<uint8_t>& bytes) {
  Bank bank;
  ErrorInfo info;
  const Status s = Bank::open(bytes, bank, &info);
  if (s == Status::invalid_argument && looks_like_kanim(bytes) && !looks_like_bank(bytes))
    fail(kBadInput, path + ": a .kanim file of one clip, not a bank (keyanim pack makes one)");
  if (s != Status::ok) fail(exit_code_of(s), offline::Error::kanim(path, info).what());
  return bank;
}

Clip load_bank_clip(const std::string& path, const Bank& bank, uint32_t i, const Globals& g) {
  Clip clip;
  ErrorInfo info;
  const Status s = bank.clip(i, clip, &info, tool_limits(g));
  if (s != Status::ok) fail(exit_code_of(s), offline::Error::kanim(path, info).what());
  return clip;
}

std::optional<MemberPath> member_path(const std::string& path) {
  struct stat st;
  if (path == "-" || ::stat(path.c_str(), &st) == 0) return std::nullopt;
  for (size_t colon = path.rfind(':'); colon != std::string::npos && colon > 0; colon = path.rfind(':', colon - 1)) {
    const std::string bank = path.substr(0, colon);
    if (::stat(bank.c_str(), &st) == 0) {
      if (!S_ISREG(st.st_mode) || colon + 1 == path.size()) return std::nullopt;
      return MemberPath{bank, path.substr(colon + 1)};
    }
  }
  return std::nullopt;
}

std::vector<uint8_t> clip_file(const Clip& clip, bool runtime) {
  return runtime ? offline::write_kanim_runtime(clip) : offline::write_kanim(offline::encoded_clip(clip));
}

std::vector<uint8_t> member_file(const MemberPath& m, const std::vector<uint8_t>& bytes, const Globals& g) {
  const Bank bank = open_bank(m.bank, bytes);
  const std::optional<uint32_t> i = bank.find(m.name);
  if (!i) fail(kBadInput, m.bank + ": no clip named '" + m.name + "' (keyanim list " + m.bank + " lists them)");
  const Clip clip = load_bank_clip(m.bank, bank, *i, g);
  return clip_file(clip, bank.runtime_profile());
}

}  // namespace keyanim::cli
