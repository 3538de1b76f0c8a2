#!/usr/bin/env python3
"""Checks that calf's documentation stays usable (the ctest entry docs.check runs it).

  (a) every relative link and image in README.md, docs/**/*.md and format/*.md resolves to a file
      inside the repository, and a link's #anchor names a heading of the page it points to;
  (b) no development-history wording ("stop N", "issue N", "third round") outside the
      change-log sections at the end of format/SPEC.md, format/CAPTURE.md and
      format/SCENE.md, nor in any command's --help;
  (c) with --command NAME=PATH (repeated): every long option of that command's --help (and of each
      of its subcommands' --help) appears as `--option` in the command's reference page, the page
      the README's command table links in the command's row.

Usage: tools/check_docs.py [--root DIR] [--command NAME=PATH ...]
Prints one line per problem (FILE:LINE: what) and exits 1 if there is any, else 0.
"""

import argparse
import os
import re
import subprocess
import sys

# "stop N", "Stop N:", "stops N-M", "the stop-N figures", "issue N", "Issue N's"; and the
# titles of tuning rounds ("Third round (...)"), capitalised so that an algorithm's first round
# of samples is not one.
HISTORY = re.compile(
    r"\b(?:[Ss]tops?|[Ii]ssues?)[ -]\d+|\b(?:Second|Third|Fourth|Fifth|Sixth|Seventh|Eighth)"
    r" round\b|\b[Rr]ound \d+\b")
# Normative specs whose change log (from this heading to the end) may name what changed when.
CHANGE_LOG_HEADING = {
    "format/SPEC.md": re.compile(r"^#+ .*change log", re.IGNORECASE),
    "format/CAPTURE.md": re.compile(r"^#+ .*change log", re.IGNORECASE),
    "format/SCENE.md": re.compile(r"^#+ .*change log", re.IGNORECASE),
}
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REF_LINK = re.compile(r"^\s*\[[^\]]+\]:\s*(\S+)")
HTML_SRC = re.compile(r"<(?:img|a)\b[^>]*?\b(?:src|href)=\"([^\"]+)\"", re.IGNORECASE)
LONG_OPTION_LINE = re.compile(r"^\s+(?:-\w,\s*)?(--[A-Za-z0-9][A-Za-z0-9-]*)")


def doc_files(root):
    files = []
    if os.path.isfile(os.path.join(root, "README.md")):
        files.append("README.md")
    if os.path.isfile(os.path.join(root, "CHANGELOG.md")):
        files.append("CHANGELOG.md")
    for base, dirs, names in os.walk(os.path.join(root, "docs")):
        dirs.sort()
        for name in sorted(names):
            if name.endswith(".md"):
                files.append(os.path.relpath(os.path.join(base, name), root))
    fmt = os.path.join(root, "format")
    for name in sorted(os.listdir(fmt)):
        if name.endswith(".md"):
            files.append("format/" + name)
    return files


def unfenced_lines(text):
    """Yields (line number, line) outside fenced code blocks."""
    fence = None
    for number, line in enumerate(text.split("\n"), 1):
        stripped = line.lstrip()
        if fence is None and (stripped.startswith("```") or stripped.startswith("~~~")):
            fence = stripped[:3]
            continue
        if fence is not None:
            if stripped.startswith(fence):
                fence = None
            continue
        yield number, line


def prose_lines(text):
    """Yields (line number, line) outside fenced code blocks, inline code removed."""
    for number, line in unfenced_lines(text):
        yield number, re.sub(r"`[^`]*`", "``", line)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"`", "", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache):
    if path not in cache:
        found = set()
        counts = {}
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for _, line in unfenced_lines(text):
            m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
            if m:
                base = slug(m.group(1))
                n = counts.get(base, 0)
                counts[base] = n + 1
                found.add(base if n == 0 else f"{base}-{n}")
            for explicit in re.findall(r"<a\s+(?:name|id)=\"([^\"]+)\"", line):
                found.add(explicit)
        cache[path] = found
    return cache[path]


def check_links(root, rel, text, problems, anchor_cache):
    here = os.path.dirname(os.path.join(root, rel))
    real_root = os.path.realpath(root)
    for number, line in prose_lines(text):
        targets = LINK.findall(line) + HTML_SRC.findall(line)
        m = REF_LINK.match(line)
        if m:
            targets.append(m.group(1))
        for target in targets:
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                continue  # http:, https:, mailto:
            path_part, _, anchor = target.partition("#")
            if path_part:
                resolved = os.path.realpath(os.path.join(here, path_part))
                if not (resolved == real_root or resolved.startswith(real_root + os.sep)):
                    problems.append(f"{rel}:{number}: link '{target}' leaves the repository")
                    continue
                if not os.path.exists(resolved):
                    problems.append(f"{rel}:{number}: link '{target}' names no file")
                    continue
            else:
                resolved = os.path.join(root, rel)
            if anchor and resolved.endswith(".md") and os.path.isfile(resolved):
                if anchor not in anchors(resolved, anchor_cache):
                    problems.append(f"{rel}:{number}: link '{target}': no heading '#{anchor}' in "
                                    f"{os.path.relpath(resolved, root)}")


def check_history(rel, text, problems):
    log = CHANGE_LOG_HEADING.get(rel)
    for number, line in enumerate(text.split("\n"), 1):
        if log is not None and log.match(line):
            return
        m = HISTORY.search(line)
        if m:
            problems.append(f"{rel}:{number}: development history '{m.group(0)}' (say what holds "
                            "now; the history belongs in git)")


def command_pages(root):
    """The README's command table: command name -> the .md page its row links first."""
    pages = {}
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        for line in f:
            if not line.startswith("|"):
                continue
            cells = line.strip().strip("|").split("|")
            m = re.match(r"^\s*\[?`(calf-[a-z-]+)`", cells[0])
            if not m:
                continue
            for _, target in re.findall(r"\[([^\]]*)\]\(([^)#\s]+\.md)(?:#[^)]*)?\)", line):
                pages.setdefault(m.group(1), os.path.normpath(target))
                break
    return pages


def help_text(path, args):
    result = subprocess.run([path] + args + ["--help"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, timeout=60)
    return result.returncode, result.stdout


def check_command(root, name, path, pages, problems):
    if name not in pages:
        problems.append(f"README.md: the command table has no row for {name} linking its page")
        return
    page = pages[name]
    try:
        with open(os.path.join(root, page), encoding="utf-8") as f:
            page_text = f.read()
    except OSError:
        problems.append(f"README.md: {name}'s page {page} cannot be read")
        return
    helps = [([], None)]
    done = 0
    while done < len(helps):
        sub, _ = helps[done]
        code, text = help_text(path, sub)
        helps[done] = (sub, text)
        done += 1
        where = " ".join([name] + sub) + " --help"
        if code != 0:
            problems.append(f"{where}: exit status {code}")
            continue
        for number, line in enumerate(text.split("\n"), 1):
            m = HISTORY.search(line)
            if m:
                problems.append(f"{where}:{number}: development history '{m.group(0)}'")
        # CLI11 lists subcommands under "Subcommands:", one per line, two spaces in.
        in_subcommands = False
        for line in text.split("\n"):
            if line.startswith("Subcommands:"):
                in_subcommands = True
                continue
            if in_subcommands:
                m = re.match(r"^  ([a-z][a-z0-9-]*)\b", line)
                if m and not sub:
                    helps.append(([m.group(1)], None))
                elif not line.strip() or not line.startswith(" "):
                    in_subcommands = False
        for line in text.split("\n"):
            m = LONG_OPTION_LINE.match(line)
            if not m:
                continue
            option = m.group(1)
            if not re.search(re.escape(option) + r"(?![A-Za-z0-9-])", page_text):
                problems.append(f"{page}: {where} lists {option}, the page never names it")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--command", action="append", default=[], metavar="NAME=PATH")
    args = parser.parse_args()
    root = os.path.realpath(args.root)
    problems = []
    anchor_cache = {}
    for rel in doc_files(root):
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            text = f.read()
        check_links(root, rel, text, problems, anchor_cache)
        check_history(rel, text, problems)
    pages = command_pages(root)
    for entry in args.command:
        name, _, path = entry.partition("=")
        check_command(root, name, path, pages, problems)
    for problem in problems:
        print(problem)
    if problems:
        print(f"check_docs: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
