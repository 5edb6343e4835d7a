// A bank file in memory for Bank::open_file: mapped whole, so that its members are sampled in
// place, except the part that opening reads (header, index, dictionary, skeletons, checksum),
// which is read into private pages.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "keyanim/status.h"

namespace keyanim::internal {

struct BankFile {
  std::shared_ptr<const void> storage;  // keeps the mapping; unmapped with its last user
  std::span<const uint8_t> bytes;       // the whole file, page-aligned
};

// io_error (naming `path`) if the file cannot be opened, is not a regular file or cannot be
// mapped or read.
Status map_bank_file(const std::string& path, BankFile& out, ErrorInfo* err);

}  // namespace keyanim::internal
