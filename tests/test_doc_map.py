#!/usr/bin/env python3
"""The map stays true: the paths that README.md and docs/architecture.md name exist, and
docs/architecture.md's kernel tree names every file under kernels/ and nothing else.

What counts as a named path (the rule, also in docs/testing.md):
- a word in `backticks` or in a fenced code block that starts with one of the source folders
  (host/ kernels/ bvh/ scenes/ tests/ tools/ docs/ .ci/), read from the repository root; outputs
  (build/, render.exr) and example names (scene.glb) start with none of them and are not checked;
- the target of a Markdown link [text](target) that is not a URL, read from the page's folder;
  with a #fragment, the heading must exist in the target page (GitHub's anchor rule);
- `*` in a path is a glob that must match at least one file; words with `...`, `…`, `[`, `{`,
  `<` or upper-case placeholders such as NAME (`kernels/<stage>.cl`, `tools/studies/NAME.py`) are
  patterns or examples, not paths.

The kernel tree is the fenced block of docs/architecture.md that starts with the line `kernels/`:
each line that names entries holds them before the first run of two spaces, indented two spaces
per folder level below kernels/ (a folder ends in `/`); the description follows. Continuation
lines start at the description column (26) or further. Every tracked file under kernels/ must be
named there, and every name must exist (the tree names files, not patterns).

Run by ctest (doc_map, unit tier) or as `python3 tests/test_doc_map.py`; --repo ROOT checks
another tree (the test of this test: a removed file or a new one left out of the tree fails).
Standard library only.
"""

import argparse
import glob
import os
import re
import subprocess
import sys
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGES = ("README.md", os.path.join("docs", "architecture.md"))
SOURCE_FOLDERS = ("host/", "kernels/", "bvh/", "scenes/", "tests/", "tools/", "docs/", ".ci/")
DESCRIPTION_COLUMN = 26
PLACEHOLDER = re.compile(r"\.\.\.|…|\[|\{|<|\b[A-Z]{3,}\b")


def slug(heading):
    """GitHub's anchor for a Markdown heading."""
    text = re.sub(r"`|\*\*|\*|_(?=\w)|(?<=\w)_", "", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(path):
    out, seen, fenced = set(), {}, False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("```"):
                fenced = not fenced
            m = None if fenced else re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
            if m:
                s = slug(m.group(1))
                n = seen.get(s, 0)
                seen[s] = n + 1
                out.add(s if n == 0 else f"{s}-{n}")
    return out


def words_of(text):
    """(word, from_code) for the words of backticked spans and fenced blocks."""
    out, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
            continue
        spans = [line] if fenced else re.findall(r"`([^`]+)`", line)
        for span in spans:
            out += span.split()
    return out


def expand(repo, path):
    """The files a named path stands for (empty when it names nothing)."""
    full = os.path.join(repo, path)
    return glob.glob(full) if "*" in path else ([full] if os.path.exists(full) else [])


def named_paths(repo, page):
    """[(what, problem)] for the paths that `page` names and that do not exist."""
    with open(os.path.join(repo, page), encoding="utf-8") as f:
        text = f.read()
    problems = []
    for word in words_of(text):
        word = word.strip("'\"(),.:;")
        if not word.startswith(SOURCE_FOLDERS) or PLACEHOLDER.search(word):
            continue
        path = word.split("#")[0]
        if not expand(repo, path):
            problems.append(f"{page}: `{word}` does not exist")
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, fragment = target.partition("#")
        full = os.path.normpath(os.path.join(repo, os.path.dirname(page), path)) if path else \
            os.path.join(repo, page)
        if not os.path.exists(full):
            problems.append(f"{page}: link ({target}) does not exist")
        elif fragment and full.endswith(".md") and fragment not in anchors(full):
            problems.append(f"{page}: link ({target}) has no heading #{fragment}")
    return problems


def kernel_tree(repo):
    """The set of paths (relative to the repository) that the architecture's kernel tree names."""
    with open(os.path.join(repo, "docs", "architecture.md"), encoding="utf-8") as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == "kernels/"
                 and i > 0 and lines[i - 1].startswith("```"))
    names, folders = set(), ["kernels/"]
    for line in lines[start + 1:]:
        if line.startswith("```"):
            break
        indent = len(line) - len(line.lstrip(" "))
        if not line.strip() or indent >= DESCRIPTION_COLUMN - 2:
            continue
        level = indent // 2
        if indent % 2 or level < 1 or level > len(folders):
            raise ValueError(f"kernel tree: bad indentation: {line!r}")
        del folders[level:]
        for entry in re.split(r"\s{2,}", line.strip())[0].split():
            path = folders[-1] + entry
            if entry.endswith("/"):
                folders.append(path)
            names.add(path)
    return names


def tree_problems(repo):
    names = kernel_tree(repo)
    problems = []
    for name in sorted(names):
        if not expand(repo, name.rstrip("/") if name.endswith("/") else name):
            problems.append(f"docs/architecture.md: kernel tree names {name}, which does not exist")
    covered = set()
    for name in names:
        if not name.endswith("/"):
            covered.update(os.path.relpath(p, repo) for p in expand(repo, name))
    git = subprocess.run(["git", "-C", repo, "ls-files", "--cached", "--others",
                          "--exclude-standard", "kernels"], capture_output=True, text=True)
    if git.returncode == 0:
        listed = git.stdout.split()
    else:  # not a git checkout: every file under kernels/
        listed = [os.path.relpath(os.path.join(d, f), repo)
                  for d, _, files in os.walk(os.path.join(repo, "kernels")) for f in files]
    for f in listed:
        if os.path.exists(os.path.join(repo, f)) and f not in covered:
            problems.append(f"docs/architecture.md: kernel tree leaves out {f}")
    return problems


class DocMap(unittest.TestCase):
    repo = REPO

    def test_named_paths_exist(self):
        problems = []
        for page in PAGES:
            problems += named_paths(self.repo, page)
        self.assertEqual(problems, [], "\n" + "\n".join(problems))

    def test_kernel_tree_names_every_kernel_file(self):
        problems = tree_problems(self.repo)
        self.assertEqual(problems, [], "\n" + "\n".join(problems))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repo", default=REPO, help="the tree to check (default: this one)")
    args, rest = ap.parse_known_args()
    DocMap.repo = os.path.abspath(args.repo)
    unittest.main(argv=[sys.argv[0]] + rest)
