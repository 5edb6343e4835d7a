#!/usr/bin/env python3
"""readme_shared.py FILE.md...: a new user has no ../shared (the maintainers' corpus and ACL
anchors), so a code block that uses it must follow a paragraph that says it is for maintainers,
and so must a command in the text that names it (issue 28, item 7).

  readme_shared.py FILE.md...     exit 0, or 1 with one line per offending place
  readme_shared.py --self-test    checks that each kind of offence is found"""
import re
import sys


def problems(text):
    found, in_code, para, para_line = [], False, [], 0
    before_block = last_para = ""  # the paragraph before the current code block; the last one ended

    def check_paragraph():
        joined = " ".join(para)
        commands = [c for c in re.findall(r"`([^`]*)`", joined) if c.startswith("keyanim ") and "../shared" in c]
        if commands and "maintainer" not in joined.lower():
            found.append(f"line {para_line}: `{commands[0]}` names ../shared in a paragraph not marked for maintainers")

    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            if not in_code:
                before_block = " ".join(para) if para else last_para
                check_paragraph()
                para = []
            in_code = not in_code
            continue
        if in_code:
            if "../shared" in line and "maintainer" not in before_block.lower():
                found.append(f"line {n}: a code block uses ../shared, which a new user does not have, after a "
                             "paragraph that does not say it is for maintainers")
            continue
        if line.strip() == "":
            check_paragraph()
            last_para = " ".join(para) if para else last_para
            para = []
        else:
            para_line = para_line if para else n
            para.append(line)
    check_paragraph()
    return found


def self_test():
    bad_block = "text\n\n```sh\n$ keyanim eval data --acl ../shared/anchors/acl_shell.tsv\n```\n"
    good_block = "For maintainers:\n```sh\nkeyanim eval ../shared/corpus\n```\n"
    bad_text = "Run `keyanim eval DIR --acl ../shared/anchors/acl_shell.tsv` to compare.\n"
    good = "For maintainers, `keyanim eval DIR --acl ../shared/anchors/acl_shell.tsv` compares.\n"
    mentions = "Tests run when `../shared/corpus/` exists.\n"  # a path, not a command
    assert len(problems(bad_block)) == 1, problems(bad_block)
    assert len(problems(bad_text)) == 1, problems(bad_text)
    assert problems(good) == [] and problems(mentions) == [] and problems(good_block) == []
    print("readme_shared: self-test passed")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    total = 0
    for path in sys.argv[1:]:
        with open(path, encoding="utf-8") as f:
            found = problems(f.read())
        for p in found:
            print(f"{path}: {p}")
        total += len(found)
    print(f"readme_shared: {total} place(s) in {len(sys.argv) - 1} file(s) that need ../shared without saying so")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())
