#!/usr/bin/env python3
"""Re-measures the figures the docs quote and rewrites them in place (tools/docs_figures.sh).

Each page holds its figures between <!-- figures:NAME --> and <!-- /figures:NAME --> on lines of
their own; a block is replaced whole with a table measured now, the command that reproduces it,
the commit, the machine and its load average when the measurement started. A second run on the
same tree changes nothing but the figures.

  tools/docs_figures.sh                   every block: tools/demo.sh (setup and build included),
                                          then the other measurements on its Release build
  tools/docs_figures.sh --only NAME ...   re-measures only these blocks (and only the parts of
                                          the demo they read)
  tools/docs_figures.sh --reuse [--only NAME ...]
                                          rewrites the blocks from the last run's outputs
                                          (build/docs-figures, build/demo) without measuring
  tools/docs_figures.sh --list            the blocks, their pages and what each one runs
  tools/docs_figures.sh --check           runs nothing: every marker pair in README.md, docs/ and
                                          format/ names a block of this script on the page it
                                          belongs to, every block has its markers, and
                                          rewriting a block is idempotent (the ctest entry
                                          docs.figures_blocks)

Environment: CALF_FIGURES_BUILD (the Release build directory, default build/release),
CALF_FIGURES_OUT (scratch, default build/docs-figures).
"""

import argparse
import datetime
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import textwrap
import time

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
OPEN = re.compile(r"^<!-- figures:([a-z0-9_-]+) -->$")
CLOSE = re.compile(r"^<!-- /figures:([a-z0-9_-]+) -->$")

# ---------------------------------------------------------------------------------------------
# Blocks: name -> (page, demo parts it reads, other measurements it needs, one-line description).
# The demo's parts: "lf" (capture, encode, ground truth and play of the interior light field:
# always run), "tiles", "vs" (visible set), "sf" (surfels).
BLOCKS = {
    "demo": ("README.md", {"lf", "tiles", "vs", "sf"}, set(),
             "the whole demo's wall time, its light field's quality and clip size"),
    "encoder": ("docs/ENCODER.md", {"lf"}, {"scenes"},
                "calf-encode at its defaults on three built-in scenes: bytes per stream, time"),
    "decoder": ("docs/DECODER.md", {"lf"}, {"scenes"},
                "calf-verify and calf-play's decode time per frame on the same clips"),
    "player": ("docs/PLAYER.md", {"lf"}, {"scenes"},
               "calf-play --headless --compare on the same clips: PSNR / SSIM, noise floor, ms"),
    "rendering": ("docs/RENDERING.md", set(), {"gl_render"},
                  "bench-gl_render: the GL ray march's frame time against the CPU reference"),
    "tiles": ("docs/TILES.md", {"lf", "tiles"}, set(),
              "the demo's tiles clip against the light field on the same poses"),
    "visibility": ("docs/VISIBILITY.md", {"lf", "vs"}, set(),
                   "the demo's visible set of the city played against the full scene"),
    "surfels": ("docs/SURFELS.md", {"lf", "sf"}, set(),
                "the demo's surfels of the factory played against the full mesh"),
    "block_codecs": ("docs/BLOCK_CODECS.md", set(), {"bc_bench"},
                     "bench-bc_bench --quick on the synthetic set: Mpix/s and PSNR per format"),
}
SCENES = ("interior", "turntable", "mirror-box")  # interior is the demo's own clip
FACE, FRAMES, GT = 64, 8, "128x128"  # the demo's light-field settings


# ---------------------------------------------------------------------------------------------
# Rewriting blocks (pure functions: --check exercises them without measuring anything).
class BlockError(Exception):
    pass


def blocks_in(text):
    """[(name, first body line index, closing line index)] of the marker pairs in text."""
    found, open_name, open_at = [], None, 0
    lines = text.split("\n")
    for i, line in enumerate(lines):
        m = OPEN.match(line)
        if m:
            if open_name is not None:
                raise BlockError(f"line {i + 1}: figures:{m.group(1)} opens inside figures:{open_name}")
            open_name, open_at = m.group(1), i
            continue
        m = CLOSE.match(line)
        if m:
            if open_name != m.group(1):
                raise BlockError(f"line {i + 1}: /figures:{m.group(1)} closes no open block")
            found.append((open_name, open_at + 1, i))
            open_name = None
        elif "<!-- figures:" in line or "<!-- /figures:" in line:
            raise BlockError(f"line {i + 1}: a figures marker must be alone on its line")
    if open_name is not None:
        raise BlockError(f"figures:{open_name} is never closed")
    names = [name for name, _, _ in found]
    for name in names:
        if names.count(name) > 1:
            raise BlockError(f"figures:{name} appears {names.count(name)} times")
    return found


def block_body(text, name):
    for found, first, last in blocks_in(text):
        if found == name:
            return "\n".join(text.split("\n")[first:last])
    raise BlockError(f"no figures:{name} block")


def replace_block(text, name, body):
    """text with block NAME's body replaced by body (no trailing newline needed)."""
    lines = text.split("\n")
    for found, first, last in blocks_in(text):
        if found == name:
            new = body.rstrip("\n").split("\n") if body.strip("\n") else []
            return "\n".join(lines[:first] + new + lines[last:])
    raise BlockError(f"no figures:{name} block")


def doc_files(root):
    files = ["README.md"] if os.path.isfile(os.path.join(root, "README.md")) else []
    for sub in ("docs", "format"):
        for base, dirs, names in os.walk(os.path.join(root, sub)):
            dirs.sort()
            files += [os.path.relpath(os.path.join(base, n), root) for n in sorted(names)
                      if n.endswith(".md")]
    return files


def check(root):
    problems, seen = [], {}
    for rel in doc_files(root):
        with open(os.path.join(root, rel), encoding="utf-8") as f:
            text = f.read()
        try:
            found = blocks_in(text)
        except BlockError as e:
            problems.append(f"{rel}: {e}")
            continue
        for name, _, _ in found:
            if name not in BLOCKS:
                problems.append(f"{rel}: figures:{name} is an unknown block (tools/docs_figures.py "
                                "does not regenerate it, so it would go stale)")
                continue
            if BLOCKS[name][0] != rel:
                problems.append(f"{rel}: figures:{name} belongs on {BLOCKS[name][0]}")
                continue
            seen[name] = rel
            body = block_body(text, name)
            if replace_block(text, name, body) != text:
                problems.append(f"{rel}: figures:{name}: rewriting with its own body changes the page")
            probe = "| a | b |\n|---|---|\n| 1 | 2 |\n"
            once = replace_block(text, name, probe)
            if replace_block(once, name, probe) != once or block_body(once, name) != probe.rstrip():
                problems.append(f"{rel}: figures:{name}: a second rewrite is not idempotent")
            if replace_block(once, name, body) != text:
                problems.append(f"{rel}: figures:{name}: rewriting does not round-trip")
    for name, (page, _, _, _) in BLOCKS.items():
        if name not in seen and os.path.isfile(os.path.join(root, page)):
            problems.append(f"{page}: has no figures:{name} block (tools/docs_figures.py writes one)")
    return problems


# ---------------------------------------------------------------------------------------------
# Measuring.
def load_average():
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = re.sub(r"\s+", " ", line.split(":", 1)[1].strip())
                    break
    except OSError:
        pass
    return f"{os.cpu_count()} cores of an {model}" if model[0] in "AEIOU" else \
        f"{os.cpu_count()} cores of a {model}"


def commit():
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, check=True,
                             capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--",
                                ".", ":!*.md"], cwd=ROOT, capture_output=True, text=True).stdout
        return out + ("+changes" if dirty.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


class Context:
    def __init__(self, build, out):
        self.build, self.out = build, out
        self.demo = os.path.join(ROOT, "build/demo")
        self.commit, self.machine = commit(), machine()
        self.date = datetime.date.today().isoformat()
        self.loads, self.seconds, self.done = {}, {}, set()

    def where(self, what):
        """(commit, date, machine) of measurement WHAT: now, or as --reuse found it noted."""
        run = STATE.get("runs", {}).get(what, {})
        return (run.get("commit", self.commit), run.get("date", self.date),
                run.get("machine", self.machine))

    def stamp(self, name, what):
        """The block's first line: who measured it, where and when."""
        at, date, host = self.where(what)
        return (f"Measured by `tools/docs_figures.sh --only {name}` at commit {at} ({date}), "
                f"Release build, on {host} (load average {self.loads[what]} when it started; GL "
                "is Mesa's llvmpipe on the CPU).")


def log(message):
    print(f"docs_figures: {message}", file=sys.stderr, flush=True)


# --reuse: the wall seconds and load averages of the last run (STATE_FILE), nothing is run again.
STATE = {"times": {}, "loads": {}}
REUSE = False
STATE_FILE = "figures-state.json"


def run(cmd, logfile, env=None, cwd=ROOT):
    """Runs cmd with its output in logfile; stops the script on failure. Returns wall seconds."""
    key = os.path.relpath(logfile, ROOT)
    if REUSE:
        if key not in STATE["times"]:
            raise SystemExit(f"docs_figures: --reuse: the last run did not write {key}")
        return STATE["times"][key]
    t0 = time.monotonic()
    with open(logfile, "w") as f:
        status = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT,
                                env=env).returncode
    if status != 0:
        with open(logfile) as f:
            sys.stderr.write("".join(f.readlines()[-20:]))
        raise SystemExit(f"docs_figures: {shlex.join(cmd)} failed (exit {status}); {logfile}")
    STATE["times"][key] = time.monotonic() - t0
    return STATE["times"][key]


def mark(ctx, what):
    """Notes the load average as the measurement WHAT starts (--reuse: the one noted then)."""
    if REUSE:
        ctx.loads[what] = STATE["loads"].get(what, "unknown")
    else:
        ctx.loads[what] = STATE["loads"][what] = load_average()
        STATE.setdefault("runs", {})[what] = dict(commit=ctx.commit, date=ctx.date,
                                                  machine=ctx.machine)


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def grab(pattern, text, what, cast=float):
    m = re.search(pattern, text, re.MULTILINE)
    if not m:
        raise SystemExit(f"docs_figures: no {what} in the output (pattern {pattern!r})")
    return tuple(cast(g) for g in m.groups()) if len(m.groups()) > 1 else cast(m.group(1))


def measure_demo(ctx, parts):
    env = dict(os.environ, CALF_DEMO_BUILD=ctx.build)
    if "tiles" not in parts:
        env["CALF_DEMO_TILES"] = ""
    if "vs" not in parts:
        env["CALF_DEMO_VS_SCENE"] = ""
    if "sf" not in parts:
        env["CALF_DEMO_SURFEL_SCENE"] = ""
    for key in ("CALF_DEMO_SCENE", "CALF_DEMO_FACE", "CALF_DEMO_FRAMES", "CALF_DEMO_GT",
                "CALF_DEMO_BLENDER"):
        env.pop(key, None)  # the demo's defaults are what the pages describe
    mark(ctx, "demo")
    report = os.path.join(ctx.out, "demo-report.txt")
    if REUSE:
        ctx.demo_report = read(report)
        return
    log(f"tools/demo.sh (parts: {', '.join(sorted(parts))}; load average {ctx.loads['demo']})")
    STATE["demo_fresh_build"] = not os.path.isfile(os.path.join(ROOT, ctx.build, "build.ninja"))
    t0 = time.monotonic()
    with open(report, "w") as f:
        proc = subprocess.Popen(["tools/demo.sh"], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)
        for line in proc.stdout:
            sys.stderr.write(line)
            f.write(line)
        if proc.wait() != 0:
            raise SystemExit(f"docs_figures: tools/demo.sh failed; {report}")
    ctx.seconds["demo"] = time.monotonic() - t0
    ctx.demo_report = read(report)


def play_summary(text):
    """The figures of one calf-play --headless --compare run."""
    psnr, ssim = grab(r"^mean PSNR ([0-9.]+) dB, mean SSIM ([0-9.]+)", text, "mean PSNR")
    floor = grab(r"^noise floor .*: mean PSNR ([0-9.]+) dB", text, "noise floor")
    decode_mean, decode_median, first, median, mbps = grab(
        r"^\d+ poses: mean decode ([0-9.]+) ms \(median ([0-9.]+)\), render first ([0-9.]+) ms "
        r"then median ([0-9.]+) ms, mean ([0-9.]+) Mbps", text, "pose summary")
    return dict(psnr=psnr, ssim=ssim, floor=floor, decode=decode_mean,
                decode_median=decode_median, first=first, render=median, mbps=mbps)


def encode_summary(text):
    seconds = grab(r"^calf-encode: wrote \S+ in ([0-9.]+) s \(colour (\w+)", text, "wrote line",
                   str)
    streams = {}
    for m in re.finditer(r"^  (colour|depth|material) +raw (\d+) +temporal (\d+) +\+spatial (\d+)"
                         r" +\+super (\d+)", text, re.MULTILINE):
        streams[m.group(1)] = tuple(int(g) for g in m.groups()[1:])
    keyframes = grab(r"colour: \d+ cells, (\d+) keyframes", text, "keyframes", int)
    rss = grab(r"peak RSS ([0-9.]+) MiB", text, "peak RSS")
    return dict(seconds=float(seconds[0]), colour=seconds[1], streams=streams,
                keyframes=keyframes, rss=rss)


def measure_scenes(ctx):
    """The light field of turntable and mirror-box at the demo's settings (interior: the demo)."""
    mark(ctx, "scenes")
    b = ctx.build
    ctx.scenes = {}
    for scene in SCENES:
        if scene == "interior":
            d, logs = ctx.demo, os.path.join(ctx.demo, "logs")
            enc = read(os.path.join(logs, "calf-encode.log"))
            play = read(os.path.join(logs, "calf-play.log"))
            clip = os.path.join(d, "interior.calf")
            capture_s = grab(r"== calf-capture +done in ([0-9.]+) s", ctx.demo_report, "capture s")
            encode_wall = grab(r"== calf-encode +done in ([0-9.]+) s", ctx.demo_report, "encode s")
            gt = os.path.join(d, "ground-truth")
        else:
            d = os.path.join(ctx.out, "scenes", scene)
            os.makedirs(d, exist_ok=True)
            if not REUSE:
                log(f"{scene}: capture, ground truth, encode, verify, play")
            capture_s = run([f"{b}/calf-capture", "--scene", scene, "--out", f"{d}/capture",
                             "--face-size", str(FACE), "--frames", str(FRAMES), "--quiet"],
                            f"{d}/capture.log")
            run([f"{b}/calf-capture", "--scene", scene, "--ground-truth", "--out", f"{d}/gt",
                 "--frames", str(FRAMES), "--gt-size", GT, "--quiet"], f"{d}/gt.log")
            clip = f"{d}/{scene}.calf"
            encode_wall = run([f"{b}/calf-encode", f"{d}/capture/manifest.json", "-o", clip],
                              f"{d}/encode.log")
            enc = read(f"{d}/encode.log")
            run([f"{b}/calf-play", clip, "--headless", "--compare", f"{d}/gt"], f"{d}/play.log")
            play = read(f"{d}/play.log")
            gt = f"{d}/gt"
        verify_s = run([f"{b}/calf-verify", clip], os.path.join(ctx.out, f"verify-{scene}.log"))
        views = read(os.path.join(d, "capture/manifest.json")).count('"name"')
        ctx.scenes[scene] = dict(clip=clip, bytes=os.path.getsize(clip), enc=encode_summary(enc),
                                 encode_wall=encode_wall, play=play_summary(play),
                                 verify=verify_s, views=views, capture_s=capture_s, gt=gt)
        if scene == "mirror-box":
            log("mirror-box: calf-play --rr")
            run([f"{b}/calf-play", clip, "--headless", "--compare", gt, "--rr"],
                f"{d}/play-rr.log")
            ctx.scenes[scene]["play_rr"] = play_summary(read(f"{d}/play-rr.log"))


def build_targets(ctx, targets):
    if REUSE:
        return
    cmd = ["cmake", "--build", ctx.build, "--target"] + targets
    log(" ".join(cmd))
    run(cmd, os.path.join(ctx.out, "build-" + "-".join(targets) + ".log"))


def measure_gl_render(ctx):
    build_targets(ctx, ["bench-gl_render"])
    mark(ctx, "gl_render")
    log("bench-gl_render")
    logfile = os.path.join(ctx.out, "gl_render.log")
    run([f"{ctx.build}/tests/bench-gl_render"] + GL_RENDER_ARGS, logfile)
    ctx.gl_render = read(logfile)


def measure_bc_bench(ctx):
    build_targets(ctx, ["bench-bc_bench"])
    mark(ctx, "bc_bench")
    log("bench-bc_bench --quick")
    logfile = os.path.join(ctx.out, "bc_bench.log")
    run([f"{ctx.build}/tests/bench-bc_bench"] + BC_BENCH_ARGS, logfile)
    ctx.bc_bench = read(logfile)


GL_RENDER_ARGS = ["--sizes", "256", "--views", "4", "9", "--repeats", "3"]
BC_BENCH_ARGS = ["--quick", "--repeats", "1"]


# ---------------------------------------------------------------------------------------------
# Writing blocks.
def para(*sentences):
    """One paragraph of prose, wrapped at 100 columns like the pages around it."""
    return textwrap.fill(" ".join(sentences), width=100, break_long_words=False,
                         break_on_hyphens=False)


def n(value):
    return f"{value:,}"


def fmt_s(value):
    return f"{value:.1f}"


def scenes_command():
    return "\n".join([
        "```",
        f"calf-capture --scene S --out cap --face-size {FACE} --frames {FRAMES}",
        f"calf-capture --scene S --out gt --ground-truth --frames {FRAMES} --gt-size {GT}",
        "calf-encode cap -o S.calf",
        "calf-verify S.calf",
        "calf-play S.calf --headless --compare gt          # mirror-box also with --rr",
        "```"])


def write_demo(ctx):
    r = ctx.demo_report
    total = grab(r"^total +([0-9.]+) s wall", r, "total")
    psnr, ssim = grab(r"^quality +mean PSNR ([0-9.]+) dB, mean SSIM ([0-9.]+)", r, "quality")
    clip = grab(r"^clip +[^:]*: ([0-9.]+) MB", r, "clip")
    floor = play_summary(read(os.path.join(ctx.demo, "logs/calf-play.log")))["floor"]
    packages = ("packages already installed" if "already installed" in r
                else "installing the missing packages")
    build = ("the Release build made from scratch" if STATE.get("demo_fresh_build")
             else "the Release build already there")
    at, date, host = ctx.where("demo")
    text = (f"The demo took **{total:.1f} s** wall on {host} (load average "
            f"{ctx.loads['demo']} when it started; {packages}, {build}; commit {at}, "
            f"{date}); its light field played at {psnr:.2f} dB PSNR, {ssim:.4f} SSIM against "
            f"ground truth (noise floor {floor:.2f} dB), from a {clip:.2f} MB clip.")
    if STATE.get("full_run_s"):
        text += (f" `tools/docs_figures.sh` re-measured it and every figures block of docs/ "
                 f"(`--list` names them) in {STATE['full_run_s']:.0f} s wall (load average "
                 f"{STATE['full_run_load']} at the end).")
    return para(text)


def write_encoder(ctx):
    rows = ["| scene | views | colour | colour bytes raw → temporal → BCn → zstd | depth bytes "
            "raw → zstd | clip bytes | colour keyframes | encode s (wall) | peak RSS MiB | "
            "PSNR / SSIM vs GT (noise floor) |",
            "|---|---:|---|---|---|---:|---:|---:|---:|---|"]
    for scene in SCENES:
        s = ctx.scenes[scene]
        e, p = s["enc"], s["play"]
        c, d = e["streams"]["colour"], e["streams"]["depth"]
        rows.append(f"| {scene} | {s['views']} | {e['colour'].upper()} | {n(c[0])} → {n(c[1])} → "
                    f"{n(c[2])} → {n(c[3])} ({c[0] / c[3]:.1f}×) | {n(d[0])} → {n(d[3])} "
                    f"({d[0] / d[3]:.1f}×) | {n(s['bytes'])} | {e['keyframes']} | "
                    f"{e['seconds']:.2f} ({s['encode_wall']:.1f}) | {e['rss']:.0f} | "
                    f"{p['psnr']:.2f} / {p['ssim']:.4f} ({p['floor']:.2f}) |")
    return "\n".join([
        para(ctx.stamp("encoder", "scenes"),
             f"Built-in scenes captured at {FACE}² faces over {FRAMES} frames with their default rigs, "
             "encoded at calf-encode's defaults; \"encode s\" is calf-encode's own figure (the wall "
             "time with reading the EXR set in brackets); PSNR / SSIM is calf-play's mean over the "
             f"{FRAMES} ground-truth poses at {GT}."), "", *rows, "", scenes_command()])


def write_decoder(ctx):
    rows = ["| clip | bytes | calf-verify s (decodes everything) | decode ms a frame, mean / "
            "median | Mbps at 24 fps |", "|---|---:|---:|---|---:|"]
    for scene in SCENES:
        s = ctx.scenes[scene]
        p = s["play"]
        rows.append(f"| {scene} | {n(s['bytes'])} | {s['verify']:.2f} | {p['decode']:.2f} / "
                    f"{p['decode_median']:.2f} | {p['mbps']:.2f} |")
    return "\n".join([
        para(ctx.stamp("decoder", "scenes"),
             f"The clips of ENCODER.md's table ({FACE}² faces, {FRAMES} frames); decode time is "
             "calf-play's view-dependent decoder along the ground-truth path, one thread, its first "
             "frame (everything visible uploaded) included in the mean."), "", *rows, "",
        scenes_command()])


def write_player(ctx):
    rows = ["| scene | PSNR / SSIM vs GT | noise floor PSNR | render ms a frame (first / median) "
            "| clip bytes |", "|---|---|---:|---|---:|"]
    for scene in SCENES:
        s = ctx.scenes[scene]
        variants = [("", s["play"])] + ([(", `--rr`", s["play_rr"])] if "play_rr" in s else [])
        for label, p in variants:
            rows.append(f"| {scene}{label} | {p['psnr']:.2f} / {p['ssim']:.4f} | {p['floor']:.2f} "
                        f"| {p['first']:.0f} / {p['render']:.0f} | {n(s['bytes'])} |")
    return "\n".join([
        para(ctx.stamp("player", "scenes"),
             f"calf-play's defaults (64 steps, one ray a pixel), GL on llvmpipe, against ground truth "
             f"at {GT} along each scene's {FRAMES}-pose eye path; the noise floor is the ground truth "
             f"against another seed. Captures at {FACE}² faces, {FRAMES} frames, the default rigs."),
             "", *rows, "", scenes_command()])


def write_rendering(ctx):
    lines = ctx.gl_render.split("\n")
    keep = [line.rstrip() for line in lines if re.match(r"^ *(size|\d+) ", line)]
    head = [line.strip() for line in lines if line.startswith("renderer:")]
    if len(keep) < 2:
        raise SystemExit("docs_figures: no table in bench-gl_render's output")
    return "\n".join([
        para(ctx.stamp("rendering", "gl_render"),
             "bench-gl_render's synthetic room (the eye between the views), the GL renderer at "
             "LightfieldRenderOptions' defaults; median of the frames (draw + read-back) after the first; "
             "`cpu-time` is the process's CPU time a frame over llvmpipe's threads; the peer is the "
             "CPU reference on the same frame with 2 threads. " + " ".join(head)), "",
        "```", *keep, "```", "",
        "```", "build/release/tests/bench-gl_render " + shlex.join(GL_RENDER_ARGS), "```"])


def write_tiles(ctx):
    r = read(os.path.join(ctx.demo, "logs/tl-encode.log"))
    tiles, tris, aw, ah, total = grab(
        r"\(tiles: (\d+) tiles, (\d+) triangles, atlas (\d+) x (\d+) BC7 at [0-9.]+ dB; (\d+) bytes",
        r, "tiles line", int)
    od_mean, od_peak = grab(r"measured over \d+ views: mean ([0-9.]+) \(bound 3\), peak ([0-9.]+)",
                            r, "overdraw")
    build_s = grab(r"^seconds .* total ([0-9.]+)", r, "build seconds")
    t = play_summary(read(os.path.join(ctx.demo, "logs/tl-play.log")))
    lf = play_summary(read(os.path.join(ctx.demo, "logs/tl-play-lightfield.log")))
    lf_bytes = os.path.getsize(os.path.join(ctx.demo, "interior.calf"))
    rows = ["| clip | bytes | PSNR / SSIM vs GT | noise floor | render ms (median) |",
            "|---|---:|---|---:|---:|",
            f"| tiles: {n(tiles)} tiles, {n(tris)} triangles, atlas {aw} × {ah}; overdraw mean "
            f"{od_mean:.2f}, peak {od_peak:.2f} (bounds 3, 5); built in {build_s:.1f} s | "
            f"{n(total)} | {t['psnr']:.2f} / {t['ssim']:.4f} | {t['floor']:.2f} | "
            f"{t['render']:.1f} |",
            f"| light field (all {FRAMES} frames) | {n(lf_bytes)} | {lf['psnr']:.2f} / "
            f"{lf['ssim']:.4f} | {lf['floor']:.2f} | {lf['render']:.1f} |"]
    return "\n".join([
        para(ctx.stamp("tiles", "demo"),
             f"The demo's tiles part: frame 0 of its interior capture ({FACE}² faces, 9 views), "
             "calf-encode --mode tiles at its defaults (budget 72,000 triangles), played with "
             f"calf-play's defaults (GL on llvmpipe) along the scene's eye path at {GT} with the scene "
             "held at frame 0, beside the light field on the same poses."), "", *rows, "", "```",
        f"calf-capture --scene interior --out cap --face-size {FACE} --frames {FRAMES}",
        "calf-encode --mode tiles cap -o tiles.calf --tiles-triangles 72000",
        "calf-encode cap -o lightfield.calf",
        "# the eye path of calf-capture --ground-truth with every pose's time set to 0:",
        "calf-capture --scene interior --ground-truth --eye-path frame0_path.json --out gt",
        "calf-play tiles.calf --headless --compare gt       # and lightfield.calf",
        "```"])


def against_full(text, what):
    m = re.search(r"^against the full scene.*$", text, re.MULTILINE)
    if not m:
        raise SystemExit(f"docs_figures: no 'against the full scene' line in {what}")
    return re.sub(r" \(an identical[^)]*\)", "", m.group(0))


def write_visibility(ctx):
    logs = os.path.join(ctx.demo, "logs")
    enc = read(os.path.join(logs, "vs-encode-visible.log"))
    play = read(os.path.join(logs, "vs-play.log"))
    kept, total_tris, pct = grab(r"visible set: .*?(\d+) of (\d+) triangles \(([0-9.]+) %\)", enc,
                                 "visible set line", str)
    segments = grab(r"(\d+) segments", enc, "segments", int)
    build_s = grab(r"== vs-encode-visible +done in ([0-9.]+) s", ctx.demo_report, "build s")
    vs_dir = os.path.join(ctx.demo, "visible-set")
    vis, full = (os.path.getsize(os.path.join(vs_dir, f)) for f in ("visible.calf", "full.calf"))
    frame = grab(r"^frame time \(([^)]*)\): (.*)$", play, "frame time", str)
    line = against_full(play, "vs-play.log")
    return "\n".join([
        para(ctx.stamp("visibility", "demo"),
             "The demo's visible-set part: the built-in `city`, its view region's perimeter "
             "(the builder's cube faces 200², 6 frames), played with calf-play's defaults (GL on "
             "llvmpipe, 320 × 240) along the scene's walk inside the region against the full scene."),
             "", "| figure | value |", "|---|---|",
             f"| triangles kept | {n(int(kept))} of {n(int(total_tris))} ({pct} %), from {segments} "
             "segments |",
             f"| calf-encode --visible-set wall s | {build_s:.1f} |",
             f"| mesh clip bytes | {n(vis)} (the full scene: {n(full)}) |",
             f"| frame time ({frame[0]}) | {frame[1]} |",
             f"| {line.split(':', 1)[0]} | {line.split(':', 1)[1].strip() if ':' in line else ''} |",
             "", "```",
             "calf-capture --scene city --export-scene scene --frames 6",
             "calf-encode --mode mesh scene -o full.calf",
             "calf-encode --mode mesh scene -o visible.calf --visible-set --visibility-face-size 200",
             "calf-capture --scene city --out walk --ground-truth --gt-size 320x240 --ao-samples 0 \\",
             "  --max-bounces 0 --spp 1 --no-noise-floor --frames 6",
             "calf-play visible.calf --headless --eye-path walk/eye_path.json --compare-clip full.calf",
             "```"])


def write_surfels(ctx):
    logs = os.path.join(ctx.demo, "logs")
    enc = read(os.path.join(logs, "sf-encode-surfels.log"))
    play = read(os.path.join(logs, "sf-play.log"))
    surfels, cands = grab(r"(\d+) surfels of (\d+) candidates", enc, "surfels line", int)
    per = grab(r"([0-9.]+) bytes per surfel", enc, "bytes per surfel")
    cand_s = grab(r"== sf-candidates +done in ([0-9.]+) s", ctx.demo_report, "candidates s")
    build_s = grab(r"== sf-encode-surfels +done in ([0-9.]+) s", ctx.demo_report, "surfels s")
    sf_dir = os.path.join(ctx.demo, "surfels")
    sb, fb = (os.path.getsize(os.path.join(sf_dir, f)) for f in ("surfels.calf", "full.calf"))
    frame = grab(r"^frame time \(([^)]*)\): (.*)$", play, "frame time", str)
    line = against_full(play, "sf-play.log")
    return "\n".join([
        para(ctx.stamp("surfels", "demo"),
             "The demo's surfel part: the built-in `factory` (28 M triangles counting instances), "
             "candidates ray-cast at a 128² G-buffer, at most 8,192 surfels a prototype, played with "
             "calf-play's defaults (GL on llvmpipe, 320 × 240) along its ground-level walk (2 poses) "
             "against the full mesh."), "", "| figure | value |", "|---|---|",
        f"| surfels | {n(surfels)} of {n(cands)} candidates, {per} bytes a surfel |",
        f"| build wall s | {cand_s + build_s:.1f} (candidates {cand_s:.1f} + surfels "
        f"{build_s:.1f}) |",
        f"| clip bytes (mesh + surfels) | {n(sb)} (the full mesh alone: {n(fb)}) |",
        f"| frame time ({frame[0]}) | {frame[1]} |",
        f"| {line.split(':', 1)[0]} | {line.split(':', 1)[1].strip() if ':' in line else ''} |",
        "", "```",
        "calf-capture --scene factory --export-scene scene --frames 2",
        "calf-capture --scene scene --surfel-candidates c.cand --surfel-resolution 128",
        "calf-encode --mode surfels scene --surfel-candidates c.cand -o surfels.calf --surfels 8192",
        "calf-encode --mode mesh scene -o full.calf",
        "calf-capture --scene factory --out walk --ground-truth --gt-size 320x240 --ao-samples 0 \\",
        "  --max-bounces 0 --spp 1 --no-noise-floor --frames 2",
        "calf-play surfels.calf --headless --eye-path walk/eye_path.json --compare-clip full.calf",
        "```"])


def write_block_codecs(ctx):
    rows = ["| format | q | encode Mpix/s | decode Mpix/s | mean PSNR dB (BC6H: log2-PSNR) |",
            "|---|---:|---:|---:|---:|"]
    for m in re.finditer(r"^(\S+) +(\d+) MEAN/synthetic +([0-9.]+) +([0-9.]+) +([0-9.]+)$",
                         ctx.bc_bench, re.MULTILINE):
        rows.append(f"| {m.group(1)} | {m.group(2)} | {m.group(3)} | {m.group(4)} | {m.group(5)} |")
    gains = [line for line in ctx.bc_bench.split("\n") if " vs BC1 range fit" in line]
    if len(rows) < 4:
        raise SystemExit("docs_figures: no MEAN/synthetic rows in bench-bc_bench's output")
    return "\n".join([
        para(ctx.stamp("block_codecs", "bc_bench"),
             "bench-bc_bench's synthetic set (512² images: gradient, value-noise texture, hard edges, "
             "white noise, procedural render; BC4 / BC5 on R / RG of the same images; BC6H on its HDR "
             "set: a 24-stop ramp, a sunlit render, log-uniform noise), one thread, means over the "
             "set (an exact image counts as 99 dB), `--quick` (BC1 q2, BC7 q2 and BC6H q2 left out). "
             + " ".join(g.strip() + "." for g in gains)), "", *rows, "",
        "```", "build/release/tests/bench-bc_bench " + shlex.join(BC_BENCH_ARGS), "```"])


WRITERS = {"demo": write_demo, "encoder": write_encoder, "decoder": write_decoder,
           "player": write_player, "rendering": write_rendering, "tiles": write_tiles,
           "visibility": write_visibility, "surfels": write_surfels,
           "block_codecs": write_block_codecs}
MEASURES = {"scenes": measure_scenes, "gl_render": measure_gl_render,
            "bc_bench": measure_bc_bench}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", nargs="+", metavar="NAME", help="re-measure these blocks")
    parser.add_argument("--list", action="store_true", help="list the blocks")
    parser.add_argument("--reuse", action="store_true",
                        help="rewrite the blocks from the last run's outputs; measures nothing")
    parser.add_argument("--check", action="store_true",
                        help="check the markers and the rewriting; measures nothing")
    parser.add_argument("--root", default=ROOT, help="with --check: the tree to check")
    args = parser.parse_args()
    if args.list:
        for name, (page, parts, needs, what) in BLOCKS.items():
            print(f"{name:13} {page:22} {what}")
        return 0
    if args.check:
        problems = check(args.root)
        for p in problems:
            print(p)
        return 1 if problems else 0
    names = args.only or list(BLOCKS)
    for name in names:
        if name not in BLOCKS:
            print(f"docs_figures: unknown block '{name}' (--list names them)", file=sys.stderr)
            return 2
    t_start = time.monotonic()
    build = os.path.join(ROOT, os.environ.get("CALF_FIGURES_BUILD", "build/release"))
    out = os.path.join(ROOT, os.environ.get("CALF_FIGURES_OUT", "build/docs-figures"))
    os.makedirs(out, exist_ok=True)
    global REUSE
    REUSE = args.reuse
    state_path = os.path.join(out, STATE_FILE)
    if os.path.isfile(state_path):
        with open(state_path) as f:
            STATE.update(json.load(f))
    elif REUSE:
        print(f"docs_figures: --reuse: no {state_path} (run without --reuse first)",
              file=sys.stderr)
        return 1
    ctx = Context(os.path.relpath(build, ROOT), out)
    parts = set().union(*(BLOCKS[name][1] for name in names))
    needs = set().union(*(BLOCKS[name][2] for name in names))
    if parts:
        measure_demo(ctx, parts)  # builds calf's commands too
    else:
        build_targets(ctx, ["calf-capture", "calf-encode", "calf-verify", "calf-play"])
    for need in ("scenes", "gl_render", "bc_bench"):
        if need in needs:
            t0 = time.monotonic()
            MEASURES[need](ctx)
            ctx.seconds[need] = time.monotonic() - t0
            log(f"{need}: {ctx.seconds[need]:.1f} s")
    if not REUSE:
        if not args.only:
            STATE["full_run_s"] = time.monotonic() - t_start
            STATE["full_run_load"] = load_average()
        elif "demo" in names:
            STATE.pop("full_run_s", None)  # the demo's figure no longer comes from a full run
        with open(state_path + ".tmp", "w") as f:
            json.dump(STATE, f, indent=1, sort_keys=True)
        os.replace(state_path + ".tmp", state_path)
    for name in names:
        page = os.path.join(ROOT, BLOCKS[name][0])
        text = read(page)
        new = replace_block(text, name, WRITERS[name](ctx))
        if new != text:
            with open(page + ".tmp", "w", encoding="utf-8") as f:
                f.write(new)
            os.replace(page + ".tmp", page)
        log(f"{BLOCKS[name][0]}: figures:{name} rewritten")
    times = ", ".join(f"{k} {v:.0f} s" for k, v in ctx.seconds.items())
    log(f"done in {time.monotonic() - t_start:.0f} s wall ({times}); load average now "
        f"{load_average()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
