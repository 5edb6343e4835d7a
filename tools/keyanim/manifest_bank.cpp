#include "manifest_bank.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include "batch.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "keyanim/bank.h"
#include "keyanim/offline/bank.h"
#include "manifest.h"
#include "settings.h"

namespace keyanim::cli {
namespace fs = std::filesystem;

std::string manifest_clip_name(const std::string& input) {
  return fs::path(mirrored_output(input, "")).replace_extension().generic_string();
}

void check_manifest_names(const std::vector<std::string>& all) {
  std::map<std::string, const std::string*> from;
  for (const std::string& in : all) {
    const std::string name = manifest_clip_name(in);
    if (std::string p = offline::bank_name_problem(name); !p.empty())
      fail(kBadInput, in + ": cannot name a clip '" + name + "': " + p);
    const auto [it, fresh] = from.emplace(name, &in);
    if (!fresh) fail(kBadInput, in + ": its clip would be named '" + name + "', as " + *it->second + "'s is (rename one)");
  }
}

namespace {

// What one input gave: its clip and the figures of its report line.
struct Slot {
  offline::EncodedClip clip;
  double max_error = 0, tolerance = 0, seconds = 0;
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json failed_line(const std::string& in, const std::string& out, const Failure& f,
                           std::chrono::steady_clock::time_point t0) {
  return {{"input", in}, {"output", out + ":" + manifest_clip_name(in)}, {"status", "failed"}, {"exit", f.code},
          {"message", f.message}, {"seconds", seconds_since(t0)}};
}

// A bank at `out` that opens and holds a clip of every input's name, and no other.
bool shard_done(const std::string& out, const std::vector<std::string>& inputs) {
  std::error_code ec;
  if (!fs::exists(out, ec)) return false;
  if (!fs::is_regular_file(out, ec)) fail(kOutputFailed, out + ": is not a regular file; not an output of keyanim");
  Bank bank;
  if (Bank::open_file(out, bank) != Status::ok || bank.clip_count() != inputs.size()) return false;
  for (const std::string& in : inputs)
    if (!bank.find(manifest_clip_name(in))) return false;
  return true;
}

Slot encode_input(const std::string& in, const offline::EncodeSettings& settings, const Globals& g) {
  const auto t0 = std::chrono::steady_clock::now();
  const offline::Motion motion = load_bvh(in, g);
  check_settings_for(settings, motion, in);
  offline::EncodeResult r;
  try {
    r = offline::encode(motion, settings);
  } catch (const offline::Error& e) {
    const Failure f = failure_of(e);  // a tolerance below float32 precision: 6, not 2
    fail(f.code, in + ": " + f.message);
  }
  return {std::move(r.clip), r.error.max_error, r.tolerance_units, seconds_since(t0)};
}

// The bank of the inputs that were encoded (none if every one failed), then their report
// lines: an input is done once its bank is in place.
int write_shard_bank(Output& output, const Args& args, const offline::EncodeSettings& settings,
                     const std::vector<std::string>& inputs, std::vector<std::optional<Slot>>& slots, Report& report,
                     const Globals& g, int code) {
  std::vector<offline::BankInput> clips;
  std::vector<size_t> from;  // clips[k] is inputs[from[k]]'s
  for (size_t i = 0; i < inputs.size(); ++i)
    if (slots[i]) clips.push_back({manifest_clip_name(inputs[i]), std::move(slots[i]->clip)}), from.push_back(i);
  if (clips.empty() && !inputs.empty()) return code;  // the temporary file goes with `output`
  offline::BankOptions o;
  o.runtime = args.has("--runtime");
  o.zstd_level = settings.zstd_level;
  const offline::WrittenBank w = or_fail(kBadInput, output.path() + ": ", [&] { return offline::write_bank(clips, o); });
  output.write(std::string_view(reinterpret_cast<const char*>(w.bytes.data()), w.bytes.size()));
  output.commit();
  Bank bank;  // the members' sizes, for the report, as a reader finds them
  if (Bank::open(w.bytes, bank) != Status::ok) fail(kInternal, output.path() + ": the bank written does not open");
  for (size_t k = 0; k < clips.size(); ++k) {
    const Slot& s = *slots[from[k]];
    report.add({{"input", inputs[from[k]]}, {"output", output.path() + ":" + clips[k].name}, {"status", "ok"},
                {"bytes", bank.entry(uint32_t(k)).size}, {"max_error", s.max_error}, {"tolerance", s.tolerance},
                {"seconds", s.seconds}});
  }
  if (g.verbosity > 0)
    std::cerr << printable(output.path()) << ": " << clips.size() << " of " << inputs.size() << " clips, " << w.skeletons
              << " skeleton" << (w.skeletons == 1 ? "" : "s") << ", " << w.bytes.size() << " bytes\n";
  return code;
}

}  // namespace

int encode_shard_bank(const Args& args, const offline::EncodeSettings& settings, const Globals& g,
                      const std::vector<std::string>& inputs, const std::set<std::string>& done, Report& report) {
  const std::string out = args.get("-o").value_or(args.get("--output").value_or(""));
  const bool skip_existing = args.has("--skip-existing");
  if (skip_existing && shard_done(out, inputs)) {
    for (const std::string& in : inputs)
      if (!done.count(in)) report.add({{"input", in}, {"output", out + ":" + manifest_clip_name(in)}, {"status", "skipped"}});
    if (g.verbosity > 0) std::cerr << printable(out) << ": holds the shard's " << inputs.size() << " clips; kept\n";
    return kOk;
  }
  Globals mine = g;
  mine.force = g.force || skip_existing;  // a damaged or partial bank is replaced
  std::vector<FileId> ids;
  for (const std::string& in : inputs)
    if (const auto id = input_id(in)) ids.push_back(*id);
  if (const auto id = input_id(*args.get("--manifest"))) ids.push_back(*id);
  Output output(out, true, mine, ids, bank_format());

  Globals quiet = g;
  quiet.verbosity = std::min(g.verbosity, 1);
  offline::EncodeSettings one = settings;
  one.threads = 1;  // files in parallel, each on one thread
  std::vector<std::optional<Slot>> slots(inputs.size());
  const int code = run_batch(inputs.size(), thread_count(args), g, [&](size_t i) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      slots[i] = encode_input(inputs[i], one, quiet);
    } catch (const Failure& f) {
      report.add(failed_line(inputs[i], out, f, t0));
      throw;
    } catch (const std::exception& e) {  // out of memory, say: still one line, then run_batch reports it
      report.add(failed_line(inputs[i], out, failure_of(e), t0));
      throw;
    }
  }, inputs);
  return write_shard_bank(output, args, settings, inputs, slots, report, g, code);
}

}  // namespace keyanim::cli
