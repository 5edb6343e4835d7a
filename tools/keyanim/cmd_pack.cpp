// keyanim pack: many clips into one bank (spec/FORMAT.md section 10). Inputs are BVH files
// (encoded), .kanim files, banks (merged) and directories of them; each clip is named after its
// path. Every name is known and checked, and the output checked, before anything is encoded.
#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include "bank_io.h"
#include "batch.h"
#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "keyanim/offline/bank.h"
#include "keyanim/offline/container.h"
#include "keyanim/offline/number_text.h"
#include "manifest.h"
#include "settings.h"

namespace keyanim::cli {

const char* const kPackHelp =
    "usage: keyanim pack IN... -o LIB.kbank [--runtime] [--dictionary auto|on|off] [--error E|E%]\n"
    "                    [--shell D|D%] [--keys MODE] [--tension T|fit] [--rotations quaternion|euler]\n"
    "                    [--level N] [-j N] [--json] [-f]\n"
    "  or:  keyanim pack --manifest LIST [IN...] -o LIB.kbank [--runtime] [...]\n"
    "Puts many clips into one bank (format 5.0; 4.1 when no clip has quaternion nodes): each\n"
    "distinct skeleton is stored once, a clip is found by name without reading the others,\n"
    "and each clip has its own checksum. IN is a .bvh file (encoded as `keyanim encode` would,\n"
    "with the options below), a .kanim file, a bank (its clips are merged in, with their names),\n"
    "or a directory: every .bvh, .kanim and .kbank below it. A clip is named after its path\n"
    "without the extension: a file's own name, or its path below the directory it was found in\n"
    "(cmu/02_01). Two clips of one name stop the run before anything is encoded. Commands that\n"
    "read a .kanim read a bank's clip as LIB.kbank:NAME.\n"
    "  -o, --output FILE     the bank (required)\n"
    "  --manifest LIST       also every path listed (one per line; '-': standard input), each\n"
    "                        named as listed, without its extension and root\n"
    "  --runtime             the runtime profile: clips sampled where they lie in the bank\n"
    "                        (memory-mapped), no dictionary\n"
    "  --dictionary MODE     archive banks: a zstd dictionary trained on the bank's own sections;\n"
    "                        auto (default) keeps it when the bank is then smaller, on always,\n"
    "                        off never\n"
    "  -j N                  threads for a BVH input's channels (default and most: one per core)\n"
    "  --json                one JSON object on standard output: the bank's clips, skeletons,\n"
    "                        bytes and dictionary\n";

namespace {

namespace fs = std::filesystem;

// One input file and the name its clip (or, for a bank, the prefix of nothing: its own names)
// takes.
struct Source {
  std::string path;
  std::string name;           // a BVH or .kanim file's clip
  std::vector<uint8_t> bytes;  // a bank or .kanim file, read in the first pass
  bool bank = false;
};

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string name_of(const fs::path& relative) {
  fs::path p = relative.lexically_normal();
  p.replace_extension();
  return p.relative_path().generic_string();  // an absolute path loses its root, as in encode --manifest
}

// Every input file and its clip's name: files as given, directories' files by their path below
// the directory, manifest entries as listed.
std::vector<Source> sources(const Args& args) {
  std::vector<Source> out;
  for (const std::string& in : args.positional()) {
    std::error_code ec;
    if (in != "-" && fs::is_directory(in, ec)) {
      const std::vector<std::string> found = expand_inputs({in}, {".bvh", ".kanim", ".kbank"});
      if (found.empty()) fail(kBadInput, in + ": no .bvh, .kanim or .kbank files found");
      for (const std::string& f : found) out.push_back({f, name_of(fs::path(f).lexically_relative(in)), {}, false});
    } else {
      out.push_back({in, name_of(fs::path(in).filename()), {}, false});
    }
  }
  if (const auto list = args.get("--manifest")) {
    for (const std::string& e : manifest_entries(read_manifest(*list))) out.push_back({e, name_of(e), {}, false});
  }
  if (out.empty()) fail(kUsage, "pack needs inputs: files, directories or --manifest LIST");
  return out;
}

// First pass: banks and .kanim files read (a bank's names are in its index), every name checked.
std::vector<std::string> read_names(std::vector<Source>& in, const Globals& g) {
  std::vector<std::string> names;
  std::map<std::string, std::string> from;  // name -> the input it came from
  auto add = [&](const std::string& name, const std::string& path) {
    if (std::string p = offline::bank_name_problem(name); !p.empty())
      fail(kBadInput, path + ": cannot name a clip '" + name + "': " + p);
    const auto [it, fresh] = from.emplace(name, path);
    if (!fresh) fail(kBadInput, path + ": its clip would be named '" + name + "', as " + it->second + "'s is (rename one)");
    names.push_back(name);
  };
  for (Source& s : in) {
    if (lower_extension(s.path) != ".bvh") {
      s.bytes = read_input(s.path, Kind::kanim, g);
      s.bank = looks_like_bank(s.bytes);
    }
    if (!s.bank) {
      add(s.name, s.path);
      continue;
    }
    const Bank bank = open_bank(s.path, s.bytes);
    for (uint32_t i = 0; i < bank.clip_count(); ++i) add(std::string(bank.entry(i).name), s.path + ":" + std::string(bank.entry(i).name));
  }
  return names;
}

// Second pass: every clip's keys, BVH inputs encoded.
std::vector<offline::BankInput> clips_of(const std::vector<Source>& in, const std::vector<std::string>& names,
                                         offline::EncodeSettings settings, const Globals& g) {
  std::vector<offline::BankInput> out;
  for (const Source& s : in) {
    if (s.bank) {
      const Bank bank = open_bank(s.path, s.bytes);
      for (uint32_t i = 0; i < bank.clip_count(); ++i)
        out.push_back({names[out.size()], offline::encoded_clip(load_bank_clip(s.path, bank, i, g))});
    } else if (!s.bytes.empty()) {
      out.push_back({names[out.size()], offline::encoded_clip(load_kanim(s.path, s.bytes, g))});
    } else {
      const offline::Motion m = load_bvh(s.path, g);
      check_settings_for(settings, m, s.path);
      out.push_back({names[out.size()], or_fail(kBadInput, s.path + ": ", [&] { return offline::encode(m, settings).clip; })});
    }
  }
  return out;
}

offline::BankDictionary dictionary_mode(const Args& args) {
  const std::string m = args.get("--dictionary").value_or("auto");
  if (m == "auto") return offline::BankDictionary::automatic;
  if (m == "on") return offline::BankDictionary::always;
  if (m == "off") return offline::BankDictionary::never;
  fail(kUsage, "--dictionary takes auto, on or off, not '" + m + "'");
}

nlohmann::json summary(const std::string& out, const offline::WrittenBank& w, const std::vector<offline::BankInput>& clips,
                       bool runtime) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : clips) list.push_back({{"name", c.name}, {"frames", c.clip.frame_count}});
  return {{"output", out}, {"profile", runtime ? "runtime" : "archive"}, {"clips", list},
          {"skeletons", w.skeletons}, {"bytes", w.bytes.size()}, {"dictionary_bytes", w.dictionary_bytes},
          {"bytes_without_dictionary", w.bytes_without_dictionary}};
}

}  // namespace

int cmd_pack(const Argv& argv, Globals& g) {
  std::set<std::string> valued{"-o", "--output", "-j", "--manifest", "--dictionary"};
  valued.insert(std::begin(kEncodeValuedOptions), std::end(kEncodeValuedOptions));
  const Args args(argv, valued, {"--json", "--runtime"});
  const std::string out = args.get("-o").value_or("");
  if (out.empty()) fail(kUsage, "pack needs -o LIB.kbank");
  if (out == "-" && args.has("--json")) fail(kUsage, "--json and the bank would both go to standard output: give -o FILE");
  const bool runtime = args.has("--runtime");
  if (runtime && args.has("--dictionary")) fail(kUsage, "--dictionary is for archive banks; a runtime bank has none");
  offline::BankOptions options;
  options.runtime = runtime;
  options.dictionary = dictionary_mode(args);
  offline::EncodeSettings settings = encode_settings(args);
  settings.threads = thread_count(args);
  options.zstd_level = settings.zstd_level;

  std::vector<Source> in = sources(args);
  std::vector<FileId> ids;
  for (const Source& s : in)
    if (const auto id = input_id(s.path)) ids.push_back(*id);
  Output output(out, true, g, ids, bank_format());
  const std::vector<std::string> names = read_names(in, g);
  const std::vector<offline::BankInput> clips = clips_of(in, names, settings, g);
  const offline::WrittenBank w = or_fail(kBadInput, out + ": ", [&] { return offline::write_bank(clips, options); });
  output.write(std::string_view(reinterpret_cast<const char*>(w.bytes.data()), w.bytes.size()));
  output.commit();
  if (args.has("--json")) {
    std::cout << json_text(summary(out, w, clips, runtime)) << "\n";
  } else if (g.verbosity > 0) {
    std::cerr << printable(out) << ": " << clips.size() << " clips, " << w.skeletons << " skeleton"
              << (w.skeletons == 1 ? "" : "s") << ", " << w.bytes.size() << " bytes ("
              << (runtime ? "runtime profile" : "archive profile")
              << (w.dictionary_bytes ? ", a dictionary of " + std::to_string(w.dictionary_bytes) + " bytes; " +
                                           std::to_string(w.bytes_without_dictionary) + " without it"
                                     : std::string(runtime ? "" : ", no dictionary"))
              << ")\n";
  }
  return kOk;
}

}  // namespace keyanim::cli
