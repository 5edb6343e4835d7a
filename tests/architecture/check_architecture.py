#!/usr/bin/env python3
"""The arrows between the folders (docs/architecture.md), checked on the sources as text.

  check_architecture.py REPO        exit 0 if every rule holds, 1 with one line per violation
  check_architecture.py --self-test builds small trees that break each rule and checks that
                                    each break is found (and that a clean tree passes)

Rules:
  1. Nothing outside tools/ includes a file of tools/, and no CMake file outside tools/ compiles
     a source of tools/ or adds one of its folders to an include path.
  2. The runtime (libkeyanim/include/keyanim/*.h, libkeyanim/src/runtime/,
     libkeyanim/src/internal/, which the runtime includes, and the C API over it:
     libkeyanim/include/keyanim.h and libkeyanim/src/c_api/) never includes an offline header
     (keyanim/offline/... or src/offline/...), and the keyanim_runtime target lists no offline
     source.
  3. README.md's layout table matches the tree: every path it names exists, and every folder at
     the top of the repository is in it.

An #include "X" is resolved as the compilers do here: first beside the including file, then in
the include directories the targets use (libkeyanim/include, libkeyanim/src, tests/). A name found
only inside tools/ (through an include path that reaches into tools/) breaks rule 1.
"""
import os
import re
import subprocess
import sys
import tempfile

SOURCE_EXT = (".c", ".cc", ".cpp", ".h", ".hpp")
INCLUDE_ROOTS = ("libkeyanim/include", "libkeyanim/src", "tests")
RUNTIME_PREFIXES = ("libkeyanim/src/runtime/", "libkeyanim/src/internal/", "libkeyanim/src/c_api/")
RUNTIME_FILES = ("libkeyanim/include/keyanim.h",)  # the C API's header
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def tracked_files(repo):
    try:
        out = subprocess.run(["git", "-C", repo, "ls-files", "-co", "--exclude-standard"],
                             check=True, capture_output=True, text=True).stdout
        return sorted(p for p in set(out.split()) if os.path.isfile(os.path.join(repo, p)))
    except (OSError, subprocess.CalledProcessError):  # not a checkout (the self-test's trees)
        files = []
        for d, _, names in os.walk(repo):
            for n in names:
                files.append(os.path.relpath(os.path.join(d, n), repo))
        return sorted(files)


def is_runtime(path):
    if path.startswith(RUNTIME_PREFIXES) or path in RUNTIME_FILES:
        return True
    return path.startswith("libkeyanim/include/keyanim/") and path.count("/") == 3


def resolve(repo, path, name):
    """Where #include "name" in `path` lands (a repository path), or None if nowhere here."""
    for base in (os.path.dirname(path),) + INCLUDE_ROOTS:
        candidate = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(os.path.join(repo, candidate)):
            return candidate
    # Not found through the include roots: through an include path into tools/, if anywhere.
    for d, _, names in os.walk(os.path.join(repo, "tools")):
        if os.path.basename(name) in names:
            candidate = os.path.relpath(os.path.join(d, os.path.basename(name)), repo)
            if candidate.endswith(name.replace("/", os.sep)):
                return candidate
    return None


def check_sources(repo, files):
    problems = []
    for path in files:
        if not path.endswith(SOURCE_EXT) or "node_modules/" in path or path.startswith("build"):
            continue
        with open(os.path.join(repo, path), encoding="utf-8", errors="replace") as f:
            lines = f.read().split("\n")
        for number, line in enumerate(lines, 1):
            m = INCLUDE_RE.match(line)
            if not m:
                continue
            name = m.group(1)
            target = resolve(repo, path, name)
            where = f"{path}:{number}: #include \"{name}\""
            if not path.startswith("tools/") and target and target.startswith("tools/"):
                problems.append(f"{where} reaches into tools/ ({target}): rule 1")
            offline = name.startswith(("keyanim/offline/", "offline/")) or (
                target is not None and target.startswith(("libkeyanim/src/offline/", "libkeyanim/include/keyanim/offline/")))
            if is_runtime(path) and offline:
                problems.append(f"{where}: the runtime includes offline code: rule 2")
    return problems


CMAKE_TOOLS_RE = re.compile(r'tools/[^\s)"]*\.(c|cc|cpp|h|hpp)\b|target_include_directories\([^)]*tools', re.S)


def check_cmake(repo, files):
    problems = []
    for path in files:
        if path.startswith("tools/") or not (path.endswith("CMakeLists.txt") or path.endswith(".cmake")):
            continue
        with open(os.path.join(repo, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        for m in CMAKE_TOOLS_RE.finditer(text):
            number = text.count("\n", 0, m.start()) + 1
            problems.append(f"{path}:{number}: compiles or includes from tools/ ({m.group(0).splitlines()[0]}): rule 1")
        if path == "libkeyanim/CMakeLists.txt":
            for m in re.finditer(r"add_library\(keyanim_runtime\b([^)]*)\)", text):
                if "src/offline/" in m.group(1):
                    problems.append(f"{path}: keyanim_runtime lists an offline source: rule 2")
    return problems


def check_readme_layout(repo, files):
    readme = os.path.join(repo, "README.md")
    if not os.path.isfile(readme):
        return []
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    m = re.search(r"^## Layout\n(.*?)(?=^## )", text, re.S | re.M)
    if not m:
        return ["README.md: no '## Layout' section: rule 3"]
    named = set()
    for row in re.findall(r"^\| (.+?) \|", m.group(1), re.M):
        named.update(p.rstrip("/") for p in re.findall(r"`([^`]+)`", row))
    problems = [f"README.md layout: `{p}` does not exist: rule 3" for p in sorted(named)
                if not os.path.exists(os.path.join(repo, p))]
    tops = sorted({f.split("/")[0] for f in files if "/" in f and not f.startswith(".")})
    problems += [f"README.md layout: the folder `{t}/` is not in the table: rule 3" for t in tops
                 if t not in named and not any(n.startswith(t + "/") for n in named)]
    return problems


def check(repo):
    files = tracked_files(repo)
    return check_sources(repo, files) + check_cmake(repo, files) + check_readme_layout(repo, files)


def self_test():
    """Each rule broken once in a small tree must be found; the clean tree must pass."""
    clean = {
        "libkeyanim/include/keyanim/clip.h": '#include "keyanim/status.h"\n',
        "libkeyanim/include/keyanim/status.h": "",
        "libkeyanim/include/keyanim/offline/bvh.h": '#include "keyanim/clip.h"\n',
        "libkeyanim/src/runtime/load.cpp": '#include "keyanim/clip.h"\n#include "internal/format.h"\n',
        "libkeyanim/src/internal/format.h": "",
        "libkeyanim/include/keyanim.h": "",
        "libkeyanim/src/c_api/sample.cpp": '#include "keyanim.h"\n#include "keyanim/clip.h"\n',
        "libkeyanim/src/offline/encode.cpp": '#include "keyanim/offline/bvh.h"\n',
        "libkeyanim/CMakeLists.txt": "add_library(keyanim_runtime src/runtime/load.cpp)\n",
        "tools/keyanim/io.h": "",
        "tools/keyanim/main.cpp": '#include "io.h"\n#include "keyanim/offline/bvh.h"\n',
        "bench/bench.cpp": '#include "keyanim/offline/bvh.h"\n',
        "bench/CMakeLists.txt": "add_executable(b bench.cpp)\n",
        "README.md": "# x\n## Layout\n| path | what |\n|---|---|\n| `libkeyanim/` | l |\n| `tools/keyanim/` | t |\n"
                     "| `bench/` | b |\n\n## Next\n",
    }
    breaks = {
        "a bench including a tool header": ("bench/bench.cpp", '#include "io.h"\n'),
        "a test including tools/ by path": ("tests/t.cpp", '#include "../tools/keyanim/io.h"\n'),
        "CMake compiling a tool source": ("python/CMakeLists.txt", "add_library(m ${X}/tools/keyanim/report.cpp)\n"),
        "CMake including a tool folder": ("bench/CMakeLists.txt", "target_include_directories(b PRIVATE ${P}/tools/keyanim)\n"),
        "a runtime source including an offline header": ("libkeyanim/src/runtime/load.cpp", '#include "keyanim/offline/bvh.h"\n'),
        "a runtime public header including offline": ("libkeyanim/include/keyanim/clip.h", '#include "offline/encode/verify.h"\n'),
        "an internal header including offline": ("libkeyanim/src/internal/format.h", '#include "keyanim/offline/bvh.h"\n'),
        "a C API source including offline": ("libkeyanim/src/c_api/sample.cpp", '#include "keyanim/offline/fk.h"\n'),
        "the C API header including offline": ("libkeyanim/include/keyanim.h", '#include "keyanim/offline/bvh.h"\n'),
        "the runtime target listing an offline source":
            ("libkeyanim/CMakeLists.txt", "add_library(keyanim_runtime src/runtime/load.cpp src/offline/encode.cpp)\n"),
        "a folder the README's layout does not name": ("docs/a.md", ""),
    }

    def make(tree, files):
        for rel, text in files.items():
            full = os.path.join(tree, rel)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w") as f:
                f.write(text)

    failures = 0
    with tempfile.TemporaryDirectory() as tree:
        make(tree, clean)
        found = check(tree)
        if found:
            print("self-test: the clean tree was flagged:", *found, sep="\n  ")
            failures += 1
    caught = 0
    for what, (rel, text) in breaks.items():
        with tempfile.TemporaryDirectory() as tree:
            files = dict(clean)
            files[rel] = files.get(rel, "") + text
            make(tree, files)
            if check(tree):
                caught += 1
            else:
                print(f"self-test: not caught: {what}")
                failures += 1
    print(f"self-test: {caught} of {len(breaks)} breaks caught; clean tree {'flagged' if failures > len(breaks) - caught else 'passes'}")
    return 1 if failures else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 2
    problems = check(sys.argv[1])
    for p in problems:
        print(p)
    print(f"architecture: {len(problems)} violation(s) of docs/architecture.md's rules")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
