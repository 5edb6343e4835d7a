// keyanim list: a bank's index (spec/FORMAT.md section 10), read without opening any clip.
#include <cstdio>
#include <iostream>

#include "bank_io.h"
#include "commands.h"
#include "escape.h"
#include "io.h"

namespace keyanim::cli {

const char* const kListHelp =
    "usage: keyanim list LIB.kbank [--json]\n"
    "Lists a bank's clips from its index alone: position, name, frames, frame rate, duration,\n"
    "skeleton and bytes. A clip is read as LIB.kbank:NAME by decode, sample, info, verify and\n"
    "view; keyanim unpack writes them all as files of their own.\n"
    "  --json                one JSON object on standard output: the bank's profile, bytes,\n"
    "                        skeletons and dictionary, and a \"clips\" array\n";

namespace {

nlohmann::json bank_json(const std::string& path, const Bank& bank) {
  nlohmann::json clips = nlohmann::json::array();
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    const BankEntry e = bank.entry(i);
    clips.push_back({{"index", i}, {"name", std::string(e.name)}, {"frames", e.frame_count},
                     {"frame_time", e.frame_time}, {"duration", e.frame_count > 1 ? (e.frame_count - 1) * e.frame_time : 0.0},
                     {"skeleton", e.skeleton}, {"bytes", e.size}});
  }
  return {{"bank", path}, {"profile", bank.runtime_profile() ? "runtime" : "archive"}, {"bytes", bank.size_bytes()},
          {"skeletons", bank.skeleton_count()}, {"dictionary_bytes", bank.dictionary_bytes()}, {"clips", clips}};
}

void print_table(const std::string& path, const Bank& bank) {
  std::cout << printable(path) << ": " << (bank.runtime_profile() ? "runtime" : "archive") << " bank, "
            << bank.clip_count() << " clips, " << bank.skeleton_count() << (bank.skeleton_count() == 1 ? " skeleton, " : " skeletons, ") << bank.size_bytes()
            << " bytes, " << (bank.dictionary_bytes() ? "a dictionary of " + std::to_string(bank.dictionary_bytes()) + " bytes" : "no dictionary")
            << "\n";
  char line[96];
  std::snprintf(line, sizeof line, "%6s  %8s %8s %9s %8s %10s  %s\n", "#", "frames", "fps", "seconds", "skeleton", "bytes", "name");
  std::cout << line;
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    const BankEntry e = bank.entry(i);
    const double fps = e.frame_time > 0 ? 1.0 / e.frame_time : 0.0;
    const double seconds = e.frame_count > 1 ? (e.frame_count - 1) * e.frame_time : 0.0;
    std::snprintf(line, sizeof line, "%6u  %8u %8.6g %9.3f %8u %10llu  ", i, e.frame_count, fps, seconds, e.skeleton,
                  static_cast<unsigned long long>(e.size));
    std::cout << line << printable(std::string(e.name)) << "\n";
  }
}

}  // namespace

int cmd_list(const Argv& argv, Globals& g) {
  const Args args(argv, {}, {"--json"});
  if (args.positional().size() != 1) fail(kUsage, "list takes one bank");
  const std::string in = args.positional()[0];
  const Bank bank = open_bank(in, read_input(in, Kind::kanim, g));
  if (args.has("--json")) std::cout << json_text(bank_json(in, bank)) << "\n";
  else print_table(in, bank);
  return kOk;
}

}  // namespace keyanim::cli
