// keyanim convert: a .kanim file from one profile to the other (spec/FORMAT.md section 9): the
// runtime profile, sampled where it lies, or the archive profile, the smallest. The keys and
// every value they make are the same bit for bit.
#include <iostream>

#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "keyanim/offline/container.h"

namespace keyanim::cli {

const char* const kConvertHelp =
    "usage: keyanim convert IN.kanim (--runtime | --archive) [-o OUT.kanim] [-f]\n"
    "Writes the same clip in the other profile of the format. Both sample to the same values,\n"
    "bit for bit, and hold the same keys.\n"
    "  --runtime             the runtime profile (format 5.0, or 4.0 for Euler clips): the\n"
    "                        image a player samples in place (Clip::view, keyanim_clip_view),\n"
    "                        loaded with no decoding; larger than the archive file\n"
    "  --archive             the archive profile (format 5.0, or 3.0 for Euler clips):\n"
    "                        entropy-coded, the smallest, what `keyanim encode` writes. A\n"
    "                        constant channel's single key is stored as +-1 x |value| (the\n"
    "                        same value; the archive's bytes may differ)\n"
    "  -o, --output FILE     output (default: IN with .runtime.kanim or .archive.kanim)\n"
    "The input is checked completely, its content included, before anything is written.\n";

int cmd_convert(const Argv& argv, Globals& g) {
  const Args args(argv, {"-o", "--output"}, {"--runtime", "--archive"});
  if (args.positional().size() != 1) fail(kUsage, "convert takes one input file");
  if (args.has("--runtime") == args.has("--archive")) fail(kUsage, "convert needs --runtime or --archive (one of them)");
  const bool runtime = args.has("--runtime");
  const std::string in = args.positional()[0];
  std::string out = args.get("-o").value_or("");
  if (out.empty()) {
    if (in == "-") fail(kUsage, "converting standard input needs -o FILE");
    out = swap_extension(in, runtime ? ".runtime.kanim" : ".archive.kanim");
  }
  Input input(in, g);
  Output output(out, true, g, ids_of({&input}), kanim_format(false));
  const Clip clip = load_kanim(in, input.read(Kind::kanim), g);
  const std::vector<uint8_t> bytes = or_fail(kBadInput, in + ": ", [&] {
    return runtime ? offline::write_kanim_runtime(clip) : offline::write_kanim(offline::encoded_clip(clip));
  });
  output.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  output.commit();
  if (g.verbosity > 0 && out != "-")
    std::cerr << printable(in + " -> " + out) << ": " << (runtime ? "runtime" : "archive") << " profile, "
              << bytes.size() << " bytes\n";
  return kOk;
}

}  // namespace keyanim::cli
