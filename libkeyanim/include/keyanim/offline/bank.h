// Writing a bank (spec/FORMAT.md section 10): many clips in one file, each distinct skeleton once,
// archive-profile clips compressed with a zstd dictionary trained on the bank's own sections.
// Reading one is the runtime's job (keyanim/bank.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "keyanim/offline/encode.h"

namespace keyanim::offline {

struct BankInput {
  std::string name;  // a relative path without "." or ".." parts (section 10.3): bank_name_problem
  EncodedClip clip;
};

enum class BankDictionary : uint8_t {
  automatic,  // trained, and kept only if the bank is then smaller
  always,     // trained and kept whenever zstd can train one
  never,
};

struct BankOptions {
  bool runtime = false;  // the runtime profile: sampled in place, no dictionary
  BankDictionary dictionary = BankDictionary::automatic;
  std::optional<int> zstd_level;  // as write_kanim's
};

struct WrittenBank {
  std::vector<uint8_t> bytes;
  uint32_t skeletons = 0;
  uint64_t dictionary_bytes = 0;           // 0: none
  uint64_t bytes_without_dictionary = 0;   // with a dictionary: the same bank without one
};

// The bank of `clips`, in this order (its clip table's; names are also indexed in byte order).
// Throws Error (invalid_argument) for a name that breaks section 10.3, two clips of one name, or
// a clip write_kanim refuses, naming it.
WrittenBank write_bank(const std::vector<BankInput>& clips, const BankOptions& options = {});

// Why `name` cannot name a clip in a bank (section 10.3), or "" if it can.
std::string bank_name_problem(std::string_view name);

}  // namespace keyanim::offline
