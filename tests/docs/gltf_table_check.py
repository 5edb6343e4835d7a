#!/usr/bin/env python3
"""gltf_table_check.py KEYANIM REPO [CORPUS]: the README's glTF size table (under "Sizes at the
default tolerance") against what the tool writes today (issue 28, item 6: a figure that drifts
fails a test). Each row's BVH bytes and frames, its .kanim at the default 0.05% and at 0.5%, and
the .glb exports (default, --linear, --fps 30, and of the 0.5% clip) are made again and compared
cell by cell. Rows of data/ are always checked; corpus rows only with CORPUS (exit 77, skipped,
when CORPUS is given but missing).
Exit 0, or 1 with one line per stale cell. With --write as the first argument, the README's
cells are replaced by today's figures instead."""
import os
import subprocess
import sys
import tempfile

CORPUS_ROWS = {  # the table's names for corpus clips
    "CMU 01_03 climb": "cmu/assimp__01_03.bvh",
    "Bandai walk": "bandai/dataset-1_walk_normal_001.bvh",
    "assimp Boxing_Toes": "misc/assimp__Boxing_Toes.bvh",
    "MakeHuman T-pose": "misc/makehuman__tpose.bvh",
}
COLUMNS = ["frames", "BVH", ".kanim", ".glb", ".glb --linear", ".glb --fps 30", ".kanim 0.5%", ".glb 0.5%"]


def table(readme):
    text = open(readme, encoding="utf-8").read()
    lines = text.split("Sizes at the default tolerance", 1)[1].splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("| clip |"))
    header = [c.strip() for c in lines[start].strip("|").split("|")]
    assert header[1:] == COLUMNS, header
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        rows.append((cells[0], [int(c.replace(",", "")) for c in cells[1:]]))
    return rows


def made(keyanim, bvh, tmp):
    def run(*args):
        subprocess.run([keyanim, "-q", "-f", *args], check=True, capture_output=True)
    # Named after the BVH, as encode names its output by default (a .glb holds the clip's name).
    stem = os.path.splitext(os.path.basename(bvh))[0]
    os.makedirs(os.path.join(tmp, "half"), exist_ok=True)
    k, k5 = os.path.join(tmp, stem + ".kanim"), os.path.join(tmp, "half", stem + ".kanim")
    run("encode", bvh, "-o", k)
    run("encode", bvh, "-o", k5, "--error", "0.5%")
    sizes = {}
    for name, args in ((".glb", [k]), (".glb --linear", [k, "--linear"]), (".glb --fps 30", [k, "--fps", "30"]),
                       (".glb 0.5%", [k5])):
        out = os.path.join(tmp, stem + ".glb")
        run("decode", *args, "-o", out)
        sizes[name] = os.path.getsize(out)
    frames = int(next(l for l in open(bvh, "rb").read().decode("latin-1").splitlines() if l.strip().lower().startswith("frames")).split(":")[1])
    sizes.update({"frames": frames, "BVH": os.path.getsize(bvh), ".kanim": os.path.getsize(k), ".kanim 0.5%": os.path.getsize(k5)})
    return [sizes[c] for c in COLUMNS]


def main():
    write = sys.argv[1:2] == ["--write"]
    args = sys.argv[2:] if write else sys.argv[1:]
    keyanim, repo = os.path.abspath(args[0]), args[1]
    corpus = args[2] if len(args) > 2 else None
    if corpus and not os.path.isdir(corpus):
        print(f"gltf_table_check: {corpus} not found: skipped")
        return 77
    readme = os.path.join(repo, "README.md")
    text = open(readme, encoding="utf-8").read()
    problems, checked = [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for clip, cells in table(readme):
            if clip.startswith("`data/"):
                bvh = os.path.join(repo, clip.split("`")[1])
            elif corpus and os.path.isdir(corpus):
                bvh = os.path.join(corpus, CORPUS_ROWS[clip.split(" (")[0]])
            else:
                print(f"gltf_table_check: {clip}: no corpus, not checked")
                continue
            checked += 1
            today = made(keyanim, bvh, tmp)
            for column, shown, now in zip(COLUMNS, cells, today):
                if shown != now:
                    problems.append(f"{clip}, {column}: the README shows {shown:,}, the tool makes {now:,}")
            old = "| " + " | ".join([clip] + [f"{c:,}" for c in cells]) + " |"
            text = text.replace(old, "| " + " | ".join([clip] + [f"{c:,}" for c in today]) + " |")
    if write:
        open(readme, "w", encoding="utf-8").write(text)
        print(f"gltf_table_check: {len(problems)} cell(s) rewritten in {readme}")
        return 0
    for p in problems:
        print("gltf_table_check:", p)
    print(f"gltf_table_check: {checked} rows checked, {len(problems)} stale cell(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
