// keyanim unpack: every clip of a bank as a .kanim file of its own, OUTDIR/NAME.kanim. A name's
// parts are directories below OUTDIR and never leave it (spec/FORMAT.md section 10.3).
#include <filesystem>
#include <iostream>

#include "bank_io.h"
#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"

namespace keyanim::cli {

const char* const kUnpackHelp =
    "usage: keyanim unpack LIB.kbank -o OUTDIR [--runtime | --archive] [-f]\n"
    "Writes every clip of a bank as a .kanim file of its own, OUTDIR/NAME.kanim (the parts of a\n"
    "name between '/' are directories below OUTDIR), in the bank's profile unless told. Each\n"
    "clip samples to the same values, bit for bit, as in the bank. Outputs that exist (without\n"
    "-f) or would collide stop the run before any file is written; a damaged clip is reported\n"
    "and skipped, the others written, and the exit code is then 2.\n"
    "  -o, --output DIR      the directory (created if missing)\n"
    "  --runtime             the runtime profile (format 5.0, or 4.0 for Euler clips), sampled\n"
    "                        in place\n"
    "  --archive             the archive profile (format 5.0, or 3.0 for Euler clips), the\n"
    "                        smallest\n";

int cmd_unpack(const Argv& argv, Globals& g) {
  const Args args(argv, {"-o", "--output"}, {"--runtime", "--archive"});
  if (args.positional().size() != 1) fail(kUsage, "unpack takes one bank");
  if (args.has("--runtime") && args.has("--archive")) fail(kUsage, "--runtime and --archive: one of them");
  const std::string in = args.positional()[0];
  const std::string outdir = args.get("-o").value_or("");
  if (outdir.empty() || outdir == "-") fail(kUsage, "unpack needs -o OUTDIR");
  const Bank bank = open_bank(in, read_input(in, Kind::kanim, g));
  const bool runtime = args.has("--runtime") || (bank.runtime_profile() && !args.has("--archive"));
  std::vector<std::string> inputs, outputs;
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    inputs.push_back(in + ":" + std::string(bank.entry(i).name));
    outputs.push_back((std::filesystem::path(outdir) / (std::string(bank.entry(i).name) + ".kanim")).string());
  }
  check_outputs(inputs, outputs, g);
  std::vector<FileId> bank_id;  // no output is the bank itself
  if (const auto id = input_id(in)) bank_id.push_back(*id);
  int code = kOk;
  for (uint32_t i = 0; i < bank.clip_count(); ++i) {
    try {
      const std::filesystem::path dir = std::filesystem::path(outputs[i]).parent_path();
      std::error_code mk;
      std::filesystem::create_directories(dir, mk);
      if (mk) fail(kOutputFailed, dir.string() + ": cannot create: " + mk.message());
      const std::vector<uint8_t> bytes = clip_file(load_bank_clip(in, bank, i, g), runtime);
      Output output(outputs[i], true, g, bank_id, kanim_format(false));
      output.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
      output.commit();
      if (g.verbosity > 1) std::cerr << printable(inputs[i] + " -> " + outputs[i]) << "\n";
    } catch (const Failure& f) {
      std::cerr << "keyanim: " << printable(f.message) << "\n";
      if (code == kOk) code = f.code;
    }
  }
  if (g.verbosity > 0 && code == kOk)
    std::cerr << printable(in + " -> " + outdir) << ": " << bank.clip_count() << " clips, "
              << (runtime ? "runtime" : "archive") << " profile\n";
  return code;
}

}  // namespace keyanim::cli
