#!/usr/bin/env python3
"""Mutation testing of the WGSL in shaders/: which one-line shader mutations do the tests
catch?

Mutations are generated from the source, one per site, never picked by hand: arithmetic
operators flipped (+ -, * /), comparisons inverted (< >=, > <=, == !=), logic swapped
(&& ||), min/max swapped, and assignment statements dropped. Each mutant is a copy of
shaders/ with one line changed; the test binaries (built once with the `mutants` feature,
which makes `ShaderLibrary::embedded()` read IGNIS_MUTANT_SHADERS) run against it, no
rebuild. A mutant is *caught* when a test fails or times out, *unviable* when the shader no
longer validates (tests/shaders.rs's composition check fails), and *missed* otherwise.

    cargo test --release --features mutants --no-run          # once
    scripts/wgsl_mutants.py events.wgsl --jobs 4              # one shader
    scripts/wgsl_mutants.py --all --jobs 12 --out bench/results/mutants
    scripts/wgsl_mutants.py tiles.wgsl --fail-fast --jobs 8   # stop at a mutant's first failure
    scripts/wgsl_mutants.py tiles.wgsl --out DIR --resume     # go on where a run was cut off

With --fail-fast each test runs alone, the fastest first (timed on the unmutated shaders),
and a mutant's run stops at its first failing test: the same verdicts, sooner for the
mutants a quick test catches (a survivor still runs every test).

With --out, every verdict is also appended to DIR/wgsl-<shader>.tsv as it comes; --resume
judges only the mutants not in that file and reports them all (a run cut off by a time
limit loses only the mutants it was judging).

The test binaries are found under target/release/deps (or --bins DIR). Which tests cover
which shader is the table TESTS below.
"""

import argparse
import json
import concurrent.futures as futures
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Shader -> the tests that must catch its mutants: (test binary, libtest arguments or None:
# a name filter, `--skip NAME`). The tests that run the `ignis` command are skipped: they
# check the command line, and need the binary beside the tests.
TESTS = {
    "raster_edges.wgsl": [("raster_edges", None), ("tiles", "rotated_sprites")],
    "sprite_trim.wgsl": [("sprite_trim", None), ("looks", "trimmed")],
    "events.wgsl": [("events", None), ("trails", "parent")],
    "events_on.wgsl": [("events", None), ("trails", "parent")],
    "trail.wgsl": [("trails", None), ("looks", "reference_images"), ("tiles", "ribbons")],
    "trail_on.wgsl": [("trails", None)],
    "trail_ring.wgsl": [("trails", None), ("events", None)],
    "tiles.wgsl": [("tiles", None), ("runtime", "reversed_z")],
    "tile_lists.wgsl": [("tiles", None)],
    "splat.wgsl": [("splat", None), ("runtime", "splat reversed_z msaa")],
    "splat_accum.wgsl": [("splat", None)],
    "splat_accum64.wgsl": [("splat", None)],
    "sprite_project.wgsl": [("splat", None), ("tiles", None), ("runtime", "soft")],
    "quad.wgsl": [("tiles", None), ("rendering", "--skip render_command"),
                  ("runtime", "instances_add_up"), ("lit", None), ("looks", "reference"),
                  ("looks", "sprites_turn"), ("looks", "a_streak"),
                  ("events", "inherited_colour")],
    "integrators.wgsl": [("core_sim", None), ("stability", "--skip ignis_check")],
    "tonemap.wgsl": [("tonemap", None), ("rendering", "--skip render_command")],
    "bloom.wgsl": [("bloom", None), ("rendering", "--skip render_command")],
    "clear.wgsl": [("rendering", "--skip render_command")],
    "depth_on.wgsl": [("depth_collision", None)],
    "haze_apply.wgsl": [("haze", None)],
}

# The check that tells an unviable mutant (the shader no longer composes or validates).
VALIDATE = ("shaders", "every_entry")

SWAPS = [
    (" + ", " - "), (" - ", " + "), (" * ", " / "), (" / ", " * "),
    (" < ", " >= "), (" > ", " <= "), (" <= ", " > "), (" >= ", " < "),
    (" == ", " != "), (" != ", " == "), (" && ", " || "), (" || ", " && "),
    ("min(", "max("), ("max(", "min("),
]

ASSIGNMENT = re.compile(r"^\s*[A-Za-z_][\w.\[\]]*\s*(\+|-|\*|/)?=\s*[^=].*;\s*$")


def code_part(line):
    """The line without its trailing `//` comment."""
    at = line.find("//")
    return line if at < 0 else line[:at]


def mutants_of(text):
    """Every mutant of a shader's text: (line number, description, mutated text)."""
    lines = text.split("\n")
    out = []
    for i, line in enumerate(lines):
        code = code_part(line)
        stripped = code.strip()
        if not stripped or stripped.startswith(("#import", "@group", "@binding", "struct")):
            continue
        if re.match(r"^\s*(fn|@compute|@vertex|@fragment|override)\b", code):
            continue
        for old, new in SWAPS:
            start = 0
            while True:
                at = code.find(old, start)
                if at < 0:
                    break
                if old.strip() in "+-" and code[:at].rstrip().endswith(("(", ",", "=")):
                    start = at + 1
                    continue
                mutated = line[:at] + new + line[at + len(old):]
                out.append((i + 1, f"`{old.strip()}` → `{new.strip()}` at column {at + 1}",
                            "\n".join(lines[:i] + [mutated] + lines[i + 1:])))
                start = at + 1
        if ASSIGNMENT.match(code) and not re.match(r"^\s*(let|var|const)\b", code):
            out.append((i + 1, "statement dropped",
                        "\n".join(lines[:i] + ["// (dropped)"] + lines[i + 1:])))
    return out


def find_bins(bins_dir):
    """Test binary name -> path (the newest executable `name-<hash>`)."""
    found = {}
    for path in sorted(Path(bins_dir).glob("*-*"), key=lambda p: p.stat().st_mtime):
        if path.suffix or not os.access(path, os.X_OK) or path.is_dir():
            continue
        found[path.name.rsplit("-", 1)[0]] = path
    return found


def run_tests(bins, tests, shader_dir, timeout):
    """'failed', 'timeout' or 'passed' for the tests against the shaders in `shader_dir`."""
    env = dict(os.environ, IGNIS_MUTANT_SHADERS=str(shader_dir))
    for name, filt in tests:
        cmd = [str(bins[name]), "--test-threads", "2"] + (filt.split() if filt else [])
        try:
            r = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, timeout=timeout)
        except subprocess.TimeoutExpired:
            return "timeout"
        if r.returncode != 0:
            return "failed"
    return "passed"


def list_tests(bins, name, filt, env):
    """The names of binary `name`'s tests that libtest arguments `filt` select."""
    cmd = [str(bins[name]), "--list", "--format", "terse"] + (filt.split() if filt else [])
    out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True).stdout
    return [l[: -len(": test")] for l in out.splitlines() if l.endswith(": test")]


def run_alone(bins, name, test, env, timeout):
    """'failed', 'timeout' or 'passed' for one test run by itself; and its seconds."""
    start = time.time()
    cmd = [str(bins[name]), "--exact", test, "--test-threads", "1"]
    try:
        r = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.time() - start
    return ("failed" if r.returncode != 0 else "passed"), time.time() - start


def time_tests(bins, tests, shader_dir, timeout, jobs=1):
    """Every test of `tests` alone on the shaders in `shader_dir` (`jobs` at a time),
    fastest first: [(binary, test, seconds)]; None when one does not pass."""
    env = dict(os.environ, IGNIS_MUTANT_SHADERS=str(shader_dir))
    listed = [(name, test) for name, filt in tests for test in list_tests(bins, name, filt, env)]
    with futures.ThreadPoolExecutor(jobs) as pool:
        runs = [pool.submit(run_alone, bins, name, test, env, timeout) for name, test in listed]
        outcomes = [r.result() for r in runs]
    if any(outcome != "passed" for outcome, _ in outcomes):
        return None
    timed = [(name, test, secs) for (name, test), (_, secs) in zip(listed, outcomes)]
    return sorted(timed, key=lambda t: t[2])


def run_fail_fast(bins, order, shader_dir, timeout):
    """run_tests's verdict from the tests in `order` run one by one, stopping at the
    first that fails; each under five times its unmutated time (at least 20 s)."""
    env = dict(os.environ, IGNIS_MUTANT_SHADERS=str(shader_dir))
    for name, test, secs in order:
        outcome, _ = run_alone(bins, name, test, env, min(timeout, max(20.0, 5.0 * secs)))
        if outcome != "passed":
            return outcome
    return "passed"


def judge(args, bins, shader, mutant):
    line, what, text = mutant
    with tempfile.TemporaryDirectory(prefix="wgsl-mutant-") as tmp:
        copy = Path(tmp) / "shaders"
        shutil.copytree(ROOT / "shaders", copy)
        (copy / shader).write_text(text)
        if run_tests(bins, [VALIDATE], copy, args.timeout) != "passed":
            return (line, what, "unviable")
        if args.orders is not None:
            outcome = run_fail_fast(bins, args.orders[shader], copy, args.timeout)
        else:
            outcome = run_tests(bins, TESTS[shader], copy, args.timeout)
    return (line, what, "missed" if outcome == "passed" else "caught")


def timed_tests(args, bins, tests, copy):
    """time_tests for each of `tests`; with --resume, read from (and otherwise saved to)
    --out's timings.json, so a resumed run does not time the tests again."""
    saved = Path(args.out) / "timings.json" if args.out else None
    key = lambda t: f"{t[0]} {t[1] or ''}"
    known = json.loads(saved.read_text()) if args.resume and saved and saved.exists() else {}
    timed = {}
    for t in tests:
        timed[t] = known.get(key(t)) or time_tests(bins, [t], copy, args.timeout, args.jobs)
        if saved:
            # Saved after each binary's tests: a run cut off here keeps what it timed.
            saved.parent.mkdir(parents=True, exist_ok=True)
            known[key(t)] = timed[t]
            saved.write_text(json.dumps(known))
    return timed


def baseline(args, bins, shaders):
    """The shaders whose tests pass on the unmutated copy (a mutant of the others would
    mean nothing); those that fail are named."""
    with tempfile.TemporaryDirectory(prefix="wgsl-baseline-") as tmp:
        copy = Path(tmp) / "shaders"
        shutil.copytree(ROOT / "shaders", copy)
        if run_tests(bins, [VALIDATE], copy, args.timeout) != "passed":
            sys.exit("the shader validation test fails on the unmutated shaders")
        tests = sorted({t for s in shaders for t in TESTS[s]}, key=str)
        if args.fail_fast:
            timed = timed_tests(args, bins, tests, copy)
            failing = {t for t, order in timed.items() if order is None}
            args.orders = {
                s: sorted((x for t in TESTS[s] for x in timed[t] or []), key=lambda x: x[2])
                for s in shaders
            }
        else:
            failing = {t for t in tests if run_tests(bins, [t], copy, args.timeout) != "passed"}
    for t in sorted(failing, key=str):
        print(f"baseline: the tests {t} fail on the unmutated shaders", file=sys.stderr)
    return [s for s in shaders if not failing & set(TESTS[s])]


def read_verdicts(log):
    """The verdicts a cut-off run appended to `log`: [(line, mutation, verdict)]."""
    if not log.exists():
        return []
    rows = [l.split("\t") for l in log.read_text().splitlines() if l.strip()]
    return [(int(r[0]), r[1], r[2]) for r in rows if len(r) == 3]


def report(shader, results, seconds, fail_fast=False):
    viable = [r for r in results if r[2] != "unviable"]
    caught = [r for r in viable if r[2] == "caught"]
    missed = [r for r in viable if r[2] == "missed"]
    score = 100.0 * len(caught) / max(1, len(viable))
    lines = [
        f"# WGSL mutants: `shaders/{shader}`",
        "",
        f"`scripts/wgsl_mutants.py {shader}{' --fail-fast' if fail_fast else ''}` — tests: "
        + ", ".join(f"`{b}`" + (f" ({f})" if f else "") for b, f in TESTS[shader])
        + f"; {seconds:.0f} s.",
        "",
        "| mutants | unviable | caught | missed | score |",
        "|---|---|---|---|---|",
        f"| {len(results)} | {len(results) - len(viable)} | {len(caught)} | {len(missed)} "
        f"| {score:.1f} % |",
        "",
    ]
    if missed:
        lines += ["## Missed", "", "| line | mutation |", "|---|---|"]
        lines += [f"| {l} | {w} |" for l, w, _ in sorted(missed)]
        lines.append("")
    return "\n".join(lines), (len(results), len(viable), len(caught), score)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("shaders", nargs="*", help="shader file names (see TESTS)")
    ap.add_argument("--all", action="store_true", help="every shader in TESTS")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per test binary")
    ap.add_argument("--bins", default=str(ROOT / "target/release/deps"))
    ap.add_argument("--out", help="folder for one results file per shader")
    ap.add_argument("--list", action="store_true", help="print the mutants and stop")
    ap.add_argument("--resume", action="store_true",
                    help="judge only the mutants not already in --out's .tsv of verdicts")
    ap.add_argument("--shuffle", type=int, metavar="SEED",
                    help="judge the mutants in an order shuffled with SEED (a partial run "
                    "is then a random sample)")
    ap.add_argument("--fail-fast", action="store_true",
                    help="each test alone, fastest first; a mutant stops at its first failure")
    args = ap.parse_args()
    args.orders = None
    shaders = list(TESTS) if args.all else args.shaders
    unknown = [s for s in shaders if s not in TESTS]
    if not shaders or unknown:
        sys.exit(f"name shaders from: {', '.join(TESTS)} (unknown: {unknown})")
    bins = find_bins(args.bins)
    needed = {b for s in shaders for b, _ in TESTS[s]} | {VALIDATE[0]}
    if not args.list and needed - set(bins):
        sys.exit(f"test binaries missing in {args.bins}: {sorted(needed - set(bins))}; "
                 "build them: cargo test --release --features mutants --no-run")
    summary = []
    if not args.list:
        shaders = baseline(args, bins, shaders)
    for shader in shaders:
        mutants = mutants_of((ROOT / "shaders" / shader).read_text())
        if args.list:
            for line, what, _ in mutants:
                print(f"{shader}:{line}: {what}")
            continue
        start = time.time()
        out = Path(args.out) if args.out else None
        if out:
            out.mkdir(parents=True, exist_ok=True)
        stem = f"wgsl-{shader.replace('.wgsl', '')}"
        path = out / f"{stem}.md" if out else None
        log = out / f"{stem}.tsv" if out else None
        results = read_verdicts(log) if args.resume and log else []
        done = {(r[0], r[1]) for r in results}
        todo = [m for m in mutants if (m[0], m[1]) not in done]
        if args.shuffle is not None:
            # A run cut off by a time limit has then judged a random sample.
            random.Random(args.shuffle).shuffle(todo)
        if args.resume:
            print(f"{shader}: {len(results)} judged before, {len(todo)} to judge")
        with futures.ThreadPoolExecutor(args.jobs) as pool:
            jobs = [pool.submit(judge, args, bins, shader, m) for m in todo]
            for job in futures.as_completed(jobs):
                results.append(job.result())
                if log:
                    with log.open("a") as f:
                        f.write("\t".join(map(str, results[-1])) + "\n")
                if path and len(results) < len(mutants):
                    # Progress on disk: a run cut short keeps what it judged.
                    text, _ = report(shader, results, time.time() - start, args.fail_fast)
                    path.write_text(f"{text}\n(partial: {len(results)} of {len(mutants)})\n")
        text, row = report(shader, results, time.time() - start, args.fail_fast)
        print(text)
        summary.append((shader, row))
        if path:
            path.write_text(text)
    for shader, (n, viable, caught, score) in summary:
        print(f"{shader}: {caught}/{viable} viable caught ({score:.1f} %), {n - viable} unviable")


if __name__ == "__main__":
    main()
