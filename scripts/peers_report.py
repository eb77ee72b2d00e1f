#!/usr/bin/env python3
"""Combines the peer bench's results (scripts/peers.sh) into bench/results/peers-<adapter>.md:
per N, bevy_hanabi's frame against ignis's on each draw path, the same GPU, one run."""
import glob
import json
import os
import re
import sys

NAMES = {"sphere 1m": 1 << 20, "sphere 4m": 1 << 22, "sphere 16m": 1 << 24, "sphere 67m": 1 << 26}


def side_by_side(out, n):
    """One image of both frames, halved (`side-N.png`); the two full frames without PIL."""
    try:
        from PIL import Image
    except ImportError:
        return f"ignis-{n}.png"
    a = Image.open(os.path.join(out, f"ignis-{n}.png")).convert("RGB")
    b = Image.open(os.path.join(out, f"hanabi-{n}.png")).convert("RGB")
    half = (a.width // 2, a.height // 2)
    both = Image.new("RGB", (half[0] * 2, half[1]))
    both.paste(a.resize(half), (0, 0))
    both.paste(b.resize(half), (half[0], 0))
    both.save(os.path.join(out, f"side-{n}.png"))
    return f"side-{n}.png"


def main(out):
    hanabi_file = sorted(glob.glob(os.path.join(out, "hanabi-*.json")))[-1]
    hanabi = json.load(open(hanabi_file))
    ignis = json.load(open(os.path.join(out, "ignis-spheres.json")))
    peer = {r["n"]: r for r in hanabi["rows"]}
    lines = [
        "# ignis against bevy_hanabi: the sphere workload on one GPU",
        "",
        f"- adapter: {ignis['adapter']} ({ignis.get('driver', '')})",
        f"- peer: {hanabi['peer']}, headless, an HDR camera (`crates/bench_hanabi`)",
        "- command: `scripts/peers.sh` (ignis: `" + ignis["command"] + "`)",
        "",
        "N small additive particles in a 1 m sphere (2 s lives, gravity 0.5 m/s², drag 0.5/s, "
        "0.0092 m: 3 px at 1920×1080 from 4 m), in steady state. bevy_hanabi: the median "
        "GPU time between a timestamp before its render graph and one after the camera "
        "(its simulation, the camera's clear, the transparent pass where it draws the "
        "particles, Bevy's tonemapping), and of it Bevy's span of the transparent pass. "
        "ignis: `ignis bench presets` on `bench/scenes/sphere_*.ron`, each draw path forced "
        "in the same run, the fastest pass's update + sort/splat/tiles + draw + composite "
        "(bloom and tonemap). The ratios are bevy_hanabi's frame over ignis's, and its "
        "transparent pass over ignis's drawing (sort, splat and tiles compute, draws) (above 1: "
        "ignis is faster). Image: mean / max difference from ignis's billboards, of 255.",
        "",
        "| N | bevy_hanabi frame ms | of which its draw ms | ignis path | ignis frame ms "
        "| of which update ms | of which draw ms | ratio, frames | ratio, draws | ignis vs billboards |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for rec in ignis["records"]:
        n = NAMES.get(rec["preset"])
        if n is None or n not in peer or re.search("unlit", rec["path"]):
            continue
        p = peer[n]
        ratio = p["frame_ms"] / rec["frame_ms"] if rec["frame_ms"] > 0 else float("nan")
        # ignis's drawing: the sort, splat and tiles' compute and the draws into the target.
        draw = rec["sort_ms"] + rec["draw_ms"]
        draws = p["transparent_pass_ms"] / draw if draw > 0 else float("nan")
        lines.append(
            f"| {n:,} | {p['frame_ms']:.3f} | {p['transparent_pass_ms']:.3f} | {rec['path']} "
            f"| {rec['frame_ms']:.3f} | {rec['update_ms']:.3f} | {draw:.3f} | {ratio:.2f}× "
            f"| {draws:.2f}× | {rec['diff_mean']:.2f} / {rec['diff_max']} |"
        )
    lines += [
        "",
        "## The images",
        "",
        "The last frame of each at 1920×1080, ignis (its automatic path) on the left, "
        "bevy_hanabi on the right, halved. The sprites differ (ignis's scenes draw its soft "
        "disc, hanabi a hard-edged disc), so the piles differ in brightness at their rims.",
        "",
    ]
    for n in sorted(peer):
        side = side_by_side(out, n)
        lines.append(f"- {n:,}: ![ignis left, bevy_hanabi right](peers/{side})")
    slug = re.sub("[^a-z0-9]+", "-", ignis["adapter"].lower()).strip("-")
    path = os.path.join(os.path.dirname(out.rstrip("/")), f"peers-{slug}.md")
    open(path, "w").write("\n".join(lines) + "\n")
    print("wrote", path)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/results/peers")
