#!/usr/bin/env python3
"""The help of keyanim, read as a user reads it: help_test.py KEYANIM

- `keyanim --help` lists the commands; `keyanim help` says the same; a bare `keyanim` prints the
  usage with the list of commands on standard error and exits 1 (usage).
- For every command, `keyanim help CMD`, `keyanim CMD --help` and `keyanim --help CMD` agree;
  no option is described twice; the usage line names every option the command describes, and
  every option it names is described (by the command or among the global options); the command
  accepts every option it describes.
- Short global flags combine (-qV prints the bare version; -qv, -vq and -fq are accepted).
- With README.md as a second argument: the README's usage block (the first ``` block under
  "## Using the tool") names, for every command, exactly the options its usage lines name, so
  that the README cannot fall behind the tool (issue 28, item 6).

Also run by the newcomer check (scripts/newcomer.sh) on the installed tool.
"""
import re
import subprocess
import sys

OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def run(keyanim, *args):
    p = subprocess.run([keyanim, *args], capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


def commands_of(main_help):
    """The names listed under 'commands:' (two-space indent, name, summary)."""
    block = main_help.split("\ncommands:\n", 1)[1].split("\n\n", 1)[0]
    return [line.split()[0] for line in block.splitlines()]


def described(section):
    """Entries of an option list: lines starting '  -'; each entry is the set of its spellings."""
    entries = []
    for line in section.splitlines():
        m = re.match(r"^  (-[^ ]+(?:, -[^ ]+)*)", line)
        if m:
            entries.append({s.strip() for s in m.group(1).split(",")})
    return entries


def usage_options(text, command):
    """Options named in the usage lines: 'usage: keyanim CMD ...', its other forms ('  or:  keyanim
    CMD ...') and their indented continuations."""
    lines = text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith(f"usage: keyanim {command}"))
    usage = [lines[start]]
    for line in lines[start + 1:]:
        if not (line.startswith(" " * 8) or line.startswith(f"  or:  keyanim {command} ")):
            break
        usage.append(line)
    return set(OPTION.findall(" ".join(usage).replace(f"keyanim {command}", "")))


def readme_usage(path):
    """Per command, the options of its lines in the README's usage block; and the global line's."""
    text = open(path, encoding="utf-8").read()
    block = text.split("\n## Using the tool\n", 1)[1].split("```", 2)[1]
    per_command, global_line = {}, set()
    for line in block.splitlines():
        if line.startswith("keyanim "):
            command = line.split()[1]
            per_command.setdefault(command, set()).update(OPTION.findall(line.replace(f"keyanim {command}", "")))
        elif line.startswith("global options"):
            global_line = set(OPTION.findall(line))
    return per_command, global_line


def check_readme(keyanim, readme, commands, fail):
    per_command, global_line = readme_usage(readme)
    for c in commands:
        if c == "help":
            continue
        if c not in per_command:
            fail(f"README: the usage block has no line for {c}")
            continue
        text = run(keyanim, "help", c)[1]
        named = usage_options(text, c) - global_line
        shown = per_command[c] - global_line
        for s in sorted(named - shown):
            fail(f"README: the usage block's {c} leaves out {s}, which 'keyanim {c} --help' names")
        for s in sorted(shown - named):
            fail(f"README: the usage block's {c} names {s}, which 'keyanim {c} --help' does not")


def check_command(keyanim, command, fail):
    rc, text, err = run(keyanim, "help", command)
    if rc != 0:
        return fail(f"help {command}: exit {rc}: {err}")
    for args in ([command, "--help"], ["--help", command], ["-h", command]):
        if run(keyanim, *args)[1] != text:
            fail(f"'keyanim {' '.join(args)}' differs from 'keyanim help {command}'")
    own, _, rest = text.partition("\nglobal options")
    entries = described(own)
    spellings = [s for e in entries for s in e]
    for s in sorted({s for s in spellings if spellings.count(s) > 1}):
        fail(f"{command} --help describes {s} more than once")
    globals_ = {s for e in described(rest) for s in e}
    named = usage_options(text, command)
    for e in entries:
        if not e & named:
            fail(f"{command}: the usage line leaves out {'/'.join(sorted(e))}")
    for s in sorted(named - set(spellings) - globals_):
        fail(f"{command}: the usage line names {s}, which the help does not describe")
    for s in spellings:
        rc, _, err = run(keyanim, command, s)
        if "unknown option" in err:
            fail(f"{command} refuses {s}, which its help describes: {err.strip()}")


def main():
    keyanim = sys.argv[1]
    failures = []

    def fail(message):
        failures.append(message)
        print("FAIL:", message)

    rc, main_help, _ = run(keyanim, "--help")
    commands = commands_of(main_help)
    if rc != 0 or len(commands) < 9 or "help" not in commands:
        fail(f"--help (exit {rc}) lists the commands {commands}")
    if run(keyanim, "help")[1] != main_help:
        fail("'keyanim help' differs from 'keyanim --help'")
    rc, out, err = run(keyanim)
    if rc != 1 or out or not all(re.search(rf"^  {c} ", err, re.M) for c in commands):
        fail(f"bare keyanim: exit {rc} (expected 1), stdout {out!r}, stderr lacks the commands: {err!r}")
    for args, code in ((["help", "frobnicate"], 1), (["help", "encode", "decode"], 1), (["frobnicate"], 1)):
        rc, _, err = run(keyanim, *args)
        if rc != code or "keyanim:" not in err:
            fail(f"keyanim {' '.join(args)}: exit {rc}, expected {code} with a message: {err!r}")
    for c in commands:
        if c != "help":
            check_command(keyanim, c, fail)
    if len(sys.argv) > 2:
        check_readme(keyanim, sys.argv[2], commands, fail)

    version = run(keyanim, "--version")[1].split()[1]
    for flags in ("-qV", "-Vq"):
        rc, out, _ = run(keyanim, flags)
        if rc != 0 or out != version + "\n":
            fail(f"{flags}: exit {rc}, printed {out!r}, expected the bare version {version!r}")
    for flags in ("-qv", "-vq", "-fq", "-qf"):
        rc, _, err = run(keyanim, flags, "info", "--help")
        if rc != 0:
            fail(f"{flags} refused: exit {rc}: {err}")
    print(f"checked the help of {len(commands)} commands" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
