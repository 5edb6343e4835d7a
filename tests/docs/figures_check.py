#!/usr/bin/env python3
"""figures_check.py KEYANIM CORPUS_CLIP REPO: docs/figures.md against what its commands make
today (issue 28, item 6: a figure that drifts fails a test).

- CORPUS_CLIP (the corpus' CMU 01_03) has the SHA-256 the document quotes;
- every command of its "Regenerating" block, run in a scratch directory, writes exactly the
  committed docs/ file;
- every number the tables and the text quote is the one the regenerated figure prints: a plot's
  keys on the channel, channel and joint error, keys drawn; the clip's key count and the share of
  frames with a key; a render's largest distance and where.

Exit 0, 1 with one line per drift, 77 (skipped) without the corpus clip."""
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile


def texts(svg):
    return [re.sub(r"<[^>]+>", "", t) for t in re.findall(r"<text[^>]*>.*?</text>", svg, re.S)]


def main():
    keyanim, clip, repo = (os.path.abspath(a) for a in sys.argv[1:4])
    if not os.path.isfile(clip):
        print(f"figures_check: {clip} not found: skipped")
        return 77
    doc = open(os.path.join(repo, "docs", "figures.md"), encoding="utf-8").read()
    problems = []
    want_sha = re.search(r"SHA-256 `([0-9a-f]{64})`", doc).group(1)
    if hashlib.sha256(open(clip, "rb").read()).hexdigest() != want_sha:
        problems.append(f"{clip} is not the file docs/figures.md describes (SHA-256 {want_sha})")
    block = doc.split("## Regenerating", 1)[1].split("```sh\n", 1)[1].split("```", 1)[0]
    svgs = {}
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(clip, os.path.join(tmp, "01_03.bvh"))
        os.mkdir(os.path.join(tmp, "docs"))
        for line in block.strip().splitlines():
            args = shlex.split(line)
            assert args[0] == "keyanim", line
            out = args[args.index("-o") + 1]
            p = subprocess.run([keyanim, "-q", *args[1:]], cwd=tmp, capture_output=True, text=True)
            if p.returncode != 0:
                problems.append(f"'{line}' exits {p.returncode}: {p.stderr.strip()}")
                continue
            made = open(os.path.join(tmp, out), encoding="utf-8").read()
            svgs[os.path.basename(out)] = made
            committed = os.path.join(repo, out)
            if not os.path.isfile(committed) or open(committed, encoding="utf-8").read() != made:
                problems.append(f"{out} is not what '{line}' makes today: regenerate it")
    problems += check_numbers(doc, svgs)
    for p in problems:
        print("figures_check:", p)
    print(f"figures_check: {len(svgs)} figures made, {len(problems)} drift(s)")
    return 1 if problems else 0


def check_numbers(doc, svgs):
    problems = []

    def need(svg_name, phrase, where):
        if svg_name not in svgs:
            return problems.append(f"{where}: {svg_name} was not made")
        if not any(phrase in t for t in texts(svgs[svg_name])):
            problems.append(f"{where}: {svg_name} does not print '{phrase}' ({texts(svgs[svg_name])[1][:120]}...)")

    for row in re.findall(r"^\| `(climb-[^`]+\.svg)` \|(.*)\|$", doc, re.M):
        name, cells = row[0], [c.strip() for c in row[1].split("|")]
        if name.startswith("climb-rightarm"):
            keys, channel, joint = cells[1], cells[2], cells[3]
            if keys.endswith(" drawn"):
                drawn = svgs.get(name, "").count('class="key"')
                if drawn != int(keys.split()[0]):
                    problems.append(f"table row {name}: {keys}, the figure draws {drawn} keys")
                continue
            need(name, f"{keys.split()[0]} keys on this channel", f"table row {name}")
            need(name, f"max channel error {channel.rstrip('°')} degrees", f"table row {name}")
            need(name, f"max joint error {joint.split()[0]} file units", f"table row {name}")
        else:
            m = re.match(r"([\d.]+) \((.+)\)", cells[2])
            need(name, f"largest distance: {m.group(2)} {m.group(1)} file units", f"table row {name}")
    clip_keys = re.search(r"whole clip holds ([\d,]+) keys", doc).group(1).replace(",", "")
    need("climb-rightarm-zrot-error.svg", f" {clip_keys} in the clip", "the error-mode paragraph")
    share = re.search(r"gets a key at (\d+)% of the frames", doc).group(1)
    m = re.search(r"(\d+) keys on this channel \((\d+) frames\)", " ".join(texts(svgs.get("climb-rightarm-zrot-error.svg", ""))))
    if m and round(100 * int(m.group(1)) / int(m.group(2))) != int(share):
        problems.append(f"the error-mode paragraph: a key at {share}% of the frames, the figure: {m.group(1)} of {m.group(2)}")
    curv = re.search(r"The keys sit at the curve's feature points: (\d+) on this channel, ([\d,]+)\s+in the clip", doc)
    need("climb-rightarm-zrot-curvature.svg", f"{curv.group(1)} keys on this channel", "the curvature paragraph")
    need("climb-rightarm-zrot-curvature.svg", f" {curv.group(2).replace(',', '')} in the clip", "the curvature paragraph")
    return problems


if __name__ == "__main__":
    sys.exit(main())
