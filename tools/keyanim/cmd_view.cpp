// keyanim view: a copy of the browser viewer (viewer/, installed under share/keyanim/viewer/)
// with the clip, and optionally its original BVH, embedded: one HTML file that plays offline.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <fstream>
#include <iterator>
#include <optional>

#include "commands.h"
#include "escape.h"
#include "formats.h"
#include "io.h"
#include "svg.h"  // escape(): the same escaping serves an HTML attribute

extern char** environ;

namespace keyanim::cli {

const char* const kViewHelp =
    "usage: keyanim view IN.kanim [--against ORIG.bvh] [-o OUT.html] [--to html] [--no-open] [-f]\n"
    "Writes a copy of the browser viewer with IN (and ORIG) embedded: one HTML file that plays\n"
    "the clip as a 3D skeleton, decoded in the page, offline. Prints the file's path and opens\n"
    "it with xdg-open when a display is available (DISPLAY or WAYLAND_DISPLAY set).\n"
    "  -o, --output FILE     the page (default: a new file in the temporary directory)\n"
    "  --to html             write the page under a name that does not end in .html or .htm\n"
    "                        (without it, a name that says another format is refused)\n"
    "  --against ORIG.bvh    also embed the original, overlaid, with the largest distance per frame\n"
    "  --no-open             write and print the path only\n"
    "The viewer page is taken from $KEYANIM_VIEWER_PAGE if set, else from\n"
    "BIN/../share/keyanim/viewer/index.html (installed), else from the build tree.\n";

namespace {

namespace fs = std::filesystem;

std::string base64(const std::vector<uint8_t>& in) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (size_t i = 0; i < in.size(); i += 3) {
    const uint32_t n = uint32_t(in[i]) << 16 | (i + 1 < in.size() ? uint32_t(in[i + 1]) << 8 : 0) |
                       (i + 2 < in.size() ? uint32_t(in[i + 2]) : 0);
    out += digits[n >> 18 & 63];
    out += digits[n >> 12 & 63];
    out += i + 1 < in.size() ? digits[n >> 6 & 63] : '=';
    out += i + 2 < in.size() ? digits[n & 63] : '=';
  }
  return out;
}

// Where the page may be: the override, the install (relative to this binary), the build tree.
// KEYANIM_VIEWER_FROM_BINDIR and KEYANIM_VIEWER_FROM_BUILD are relative to the binary's folder.
std::vector<fs::path> page_candidates() {
  std::vector<fs::path> out;
  if (const char* env = std::getenv("KEYANIM_VIEWER_PAGE"); env && *env) return {fs::path(env)};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return out;
  out.push_back(exe.parent_path() / KEYANIM_VIEWER_FROM_BINDIR);
  out.push_back(exe.parent_path() / KEYANIM_VIEWER_FROM_BUILD);
  return out;
}

std::string read_page() {
  std::string searched;
  for (const fs::path& p : page_candidates()) {
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) {
      std::ifstream f(p, std::ios::binary);
      std::string page((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
      if (!f.good() && !f.eof()) fail(kUnsupported, p.string() + ": cannot read the viewer page");
      return page;
    }
    searched += (searched.empty() ? " " : ", ") + p.lexically_normal().string();
  }
  fail(kUnsupported, "the viewer page is not installed (it is built when node and npm are found at configure time); looked for" +
                         (searched.empty() ? std::string(" nothing") : searched) +
                         "; set KEYANIM_VIEWER_PAGE to a built viewer/dist/index.html");
}

std::string embedded(const char* id, const std::string& path, const std::vector<uint8_t>& bytes) {
  return std::string("<script type=\"application/octet-stream\" id=\"") + id + "\" data-name=\"" +
         svg::escape(fs::path(path).filename().string()) + "\">" + base64(bytes) + "</script>\n";
}

bool same_hierarchy(const Skeleton& a, const Skeleton& b) {
  if (a.joints.size() != b.joints.size()) return false;
  for (size_t i = 0; i < a.joints.size(); ++i)
    if (a.joints[i].parent != b.joints[i].parent || a.joints[i].end_site != b.joints[i].end_site ||
        a.joints[i].channels != b.joints[i].channels)
      return false;
  return true;
}

// A new, empty file in the temporary directory, named after the clip.
std::string temporary_page(const std::string& in) {
  std::string name = (fs::temp_directory_path() / ("keyanim-view-" + fs::path(in).stem().string() + "-XXXXXX.html")).string();
  const int fd = ::mkstemps(name.data(), 5);
  if (fd < 0) fail(kOutputFailed, name + ": cannot create: " + std::strerror(errno));
  ::close(fd);
  return name;
}

// xdg-open, when there is a display to open it on; a failure here is only a warning.
void open_in_browser(const std::string& path, const Globals& g) {
  const char* x = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  if (!(x && *x) && !(w && *w)) return;
  std::array<char*, 3> args = {const_cast<char*>("xdg-open"), const_cast<char*>(path.c_str()), nullptr};
  pid_t pid;
  if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, args.data(), environ) != 0) {
    if (g.verbosity > 0) std::cerr << "keyanim: warning: cannot run xdg-open; open the file by hand\n";
    return;
  }
  int status = 0;
  ::waitpid(pid, &status, 0);  // xdg-open hands the file to the browser and returns
}

}  // namespace

int cmd_view(const Argv& argv, Globals& g) {
  const Args args(argv, {"-o", "--output", "--against", "--to"}, {"--no-open"});
  if (args.positional().size() != 1) fail(kUsage, "view takes one .kanim file");
  const std::string in = args.positional()[0];
  std::optional<std::string> out = args.get("-o");
  const bool to_html = stated_format(args, "html");
  if (out && *out == "-") fail(kUsage, "view writes a file (its path is printed); use -o FILE.html");
  // Inputs and a named output are opened and checked before anything is read (an input is
  // never the output: exit 4; a name that says another format: exit 1), then the page is
  // found (exit 3 at once if it is missing), and only then a temporary page made for it.
  Input clip_input(in, g);
  std::optional<Input> orig_input;
  if (auto orig = args.get("--against")) orig_input.emplace(*orig, g);
  std::vector<const Input*> inputs = {&clip_input};
  if (orig_input) inputs.push_back(&*orig_input);
  std::optional<Output> named;
  if (out) named.emplace(*out, false, g, ids_of(inputs), html_format(to_html));
  const std::string page_template = read_page();
  std::optional<Output> temporary;
  if (!out) {
    out = temporary_page(in);
    Globals write = g;
    write.force = true;  // the empty file just made for it
    temporary.emplace(*out, false, write, ids_of(inputs), html_format(to_html));
  }
  Output& output = named ? *named : *temporary;

  const std::vector<uint8_t> clip_bytes = clip_input.read(Kind::kanim);
  const Clip clip = load_kanim(in, clip_bytes, g);  // the page decodes it again; a bad file fails here, clearly
  std::string embed = embedded("keyanim-embedded-clip", in, clip_bytes);
  if (orig_input) {
    const std::string& orig = orig_input->path();
    const std::vector<uint8_t> bvh = orig_input->read(Kind::bvh);
    const offline::Motion m = load_bvh_bytes(orig, bvh, g);
    if (!same_hierarchy(m.skeleton, clip.skeleton()))
      fail(kBadInput, orig + ": its hierarchy or channels differ from " + in + "'s");
    if (m.frame_count != clip.frame_count() && g.verbosity > 0)
      std::cerr << "keyanim: warning: " << orig << " has " << count_of(m.frame_count, "frame") << ", " << in << " has "
                << clip.frame_count() << "; the page compares the frames both have\n";
    embed += embedded("keyanim-embedded-original", orig, bvh);
  }

  std::string page = page_template;
  const std::string marker = "<!-- keyanim:embed -->";
  const size_t at = page.find(marker);
  if (at == std::string::npos || page.find(marker, at + 1) != std::string::npos)
    fail(kUnsupported, "the viewer page has no single embed marker; rebuild it");
  page.replace(at, marker.size(), embed);
  output.write(page);
  output.commit();
  std::cout << *out << "\n";
  if (!args.has("--no-open")) open_in_browser(*out, g);
  return kOk;
}

}  // namespace keyanim::cli
