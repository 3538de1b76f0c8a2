#!/usr/bin/env python3
"""Rewrites the generated parts of docs/commands/<command>.md from the built commands' --help.

Each page holds two generated blocks, between <!-- generated:synopsis --> and
<!-- /generated:synopsis -->, and <!-- generated:options --> and <!-- /generated:options -->:
the usage lines and every option with its type, default and description, grouped by mode. The
rest of the page (what the command is, examples, when to change the defaults) is written by hand.
Run it after adding or changing an option; docs.check (tools/check_docs.py) fails while an
option of --help is missing from its page. A second run on the same build changes nothing.

Usage: tools/docs_commands.py BUILD_DIR [COMMAND ...]   (default: every page in docs/commands/)
"""
import os
import re
import subprocess
import sys

SUBCOMMANDS = {"calf-ingest": ["seurat", "equirect"]}
# Option groups of the longer commands: (regular expression on the option's name, heading), the
# first match wins; options keep --help's order within a group.
GROUPS = {
    "calf-encode": [
        (r"^--tiles-", "Tiles mode (`--mode tiles`, [docs/TILES.md](../TILES.md))"),
        (r"^--surfels?", "Surfels mode (`--mode surfels`, [docs/SURFELS.md](../SURFELS.md))"),
        (r"^--(visible-set|visibility-|eye-height|segments-per-edge|object-granularity)",
         "Mesh mode, visible set (`--mode mesh --visible-set`, [docs/VISIBILITY.md](../VISIBILITY.md))"),
        (r"^--(analysis|analysis-only|views|frame-range)$",
         "Sharded encoding ([docs/FARM.md](../FARM.md))"),
        (r"^--(help|version|mode|output|threads|max-image-pixels|quiet|supercompression|"
         r"plain-directory)$", "Every mode"),
        (r"", "Light field (the default mode, [docs/ENCODER.md](../ENCODER.md))"),
    ],
    "calf-play": [
        (r"^--surfel-", "Surfel tracks ([docs/SURFELS.md](../SURFELS.md))"),
        (r"^--tiles-", "Tiles tracks ([docs/TILES.md](../TILES.md))"),
        (r"^--(headless|eye-path|out|format|compare|no-heat-maps|noise-floor|compare-clip|"
         r"breakdown|breakdown-lossless|contact-sheet|sheet-rows)$",
         "Headless playback and measurement"),
        (r"^--(width|height|fov|stereo|ipd|frames)$", "Window"),
        (r"^--(help|version)$", "General"),
        (r"", "Rendering and view selection ([docs/RENDERING.md](../RENDERING.md))"),
    ],
    "calf-capture": [
        (r"^--(ground-truth|eye-path|gt-size|no-noise-floor)$", "Ground truth"),
        (r"^--(export-scene|surfel-)", "Scene files and surfel candidates"),
        (r"^--(views|frame-range|join)$", "Capture shards ([docs/FARM.md](../FARM.md))"),
        (r"^--(spp|min-spp|tolerance|ao-samples|max-bounces|noise|seed|coverage)$", "Sampling"),
        (r"", "Scene, rig and output"),
    ],
}
DESCRIPTION_COLUMN = 30  # CLI11 starts an option's description here


def help_text(build, command, sub=None):
    args = [os.path.join(build, command)] + ([sub] if sub else []) + ["--help"]
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=0")
    return subprocess.run(args, stdout=subprocess.PIPE, text=True, env=env, check=True).stdout


def parse(text):
    """CLI11's --help: (intro lines, usage line, positionals, options); each entry a dict with
    'head' (the names and type) and 'desc' (its description lines)."""
    intro, usage, options, positionals = [], "", [], []
    section, entry = None, None
    for line in text.split("\n"):
        if line.startswith("Usage:"):
            usage = re.sub(r"^\S*/(calf-)", r"\1", line[len("Usage: "):])
            section = "usage"
            continue
        if section is None:
            intro.append(line)
            continue
        if line in ("Positionals:", "Options:", "Subcommands:"):
            section, entry = line[:-1], None
            continue
        if not line.strip():
            entry = None
            continue
        if section not in ("Options", "Positionals"):
            continue
        if line.startswith("  ") and not line.startswith("   "):
            m = re.match(r"^  (\S.*?)(?:\s{2,}(\S.*))?$", line)
            entry = {"head": m.group(1), "desc": [m.group(2)] if m.group(2) else []}
            (options if section == "Options" else positionals).append(entry)
        elif entry is not None:
            pad = " " * DESCRIPTION_COLUMN
            entry["desc"].append(line[len(pad):] if line.startswith(pad) else line.strip())
    return intro, usage, positionals, options


def markdown(entry, positional=False):
    head = entry["head"]
    if positional:
        name, spec = head.split()[0], " ".join(head.split()[1:])
    else:
        m = re.match(r"^((?:-\w,)?--?[\w-]+)(.*)$", head)
        name, spec = (m.group(1), m.group(2)) if m else (head, "")
    spec = spec.replace("{false}", "").strip()
    out = "- **`" + name.replace(",", ", ") + "`**" + (" `" + spec + "`" if spec else "")
    desc = entry["desc"]
    if any(re.search(r"\S\s{3,}\S", d) for d in desc[1:]):  # a table (calf-capture --rig)
        return out + " — " + desc[0] + "\n\n  ```\n" + "\n".join("  " + d for d in desc[1:]) + "\n  ```"
    return out + " — " + " ".join(d.strip() for d in desc)


def group_of(command, name):
    for pattern, heading in GROUPS.get(command, []):
        if re.search(pattern, name):
            return heading
    return "Options"


def render(build, command, subcommands):
    usage, parts = "", []
    for sub in [None] + subcommands:
        intro, sub_usage, positionals, options = parse(help_text(build, command, sub))
        text = ""
        if sub is None:
            usage = sub_usage
        else:
            usage += "\n" + sub_usage
            text += f"### `{command} {sub}`\n\n" + " ".join(x.strip() for x in intro if x.strip())
            text += "\n\n"
        if positionals:
            text += "\n".join(markdown(p, True) for p in positionals) + "\n\n"
        groups = {}
        for entry in options:
            m = re.match(r"^(?:-\w,)?(--?[\w-]+)", entry["head"])
            groups.setdefault(group_of(command, m.group(1) if m else entry["head"]), []).append(entry)
        if len(groups) == 1:
            text += "\n".join(markdown(o) for o in options) + "\n"
        else:
            for heading, entries in groups.items():
                text += f"\n**{heading}**\n\n" + "\n".join(markdown(o) for o in entries) + "\n"
        parts.append(text)
    return {"usage": usage, "options": "\n".join(parts)}


def replace_block(text, name, body):
    first, last = f"<!-- generated:{name} -->", f"<!-- /generated:{name} -->"
    i, j = text.index(first) + len(first), text.index(last)
    return text[:i] + "\n" + body.strip("\n") + "\n" + text[j:]


def main():
    if len(sys.argv) < 2:
        print(__doc__.strip().split("\n")[-1], file=sys.stderr)
        return 2
    build = sys.argv[1]
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    pages = os.path.join(root, "docs", "commands")
    commands = sys.argv[2:] or sorted(p[:-3] for p in os.listdir(pages) if p.endswith(".md"))
    for cmd in commands:
        path = os.path.join(pages, cmd + ".md")
        with open(path, encoding="utf-8") as f:
            text = f.read()
        helps = render(build, cmd, SUBCOMMANDS.get(cmd, []))
        new = replace_block(text, "synopsis", "```\n" + helps["usage"] + "\n```")
        new = replace_block(new, "options", helps["options"])
        if new != text:
            with open(path, "w", encoding="utf-8") as f:
                f.write(new)
            print(f"docs_commands: {cmd}.md rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main())
