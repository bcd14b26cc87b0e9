#!/usr/bin/env python3
"""Markdown tables from `meshpaint bench trade` JSONL files (docs/TRADE.md).

    tools/trade_summary.py docs/trade/duck.jsonl [more.jsonl ...]

Per file: PSNR by resolution and format (linear filter, mean over views), PSNR by filter and
view at one resolution, frame ratios, GPU bytes, the seam jumps and the BVH presets.
"""
import json
import sys
from collections import defaultdict


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None


def fmt(value, digits=1):
    return "–" if value is None else f"{value:.{digits}f}"


def summarise(path):
    rows = [json.loads(line) for line in open(path) if line.strip()]
    meta = next(r for r in rows if r["kind"] == "meta")
    configs = [r for r in rows if r["kind"] == "config"]
    baselines = [r for r in rows if r["kind"] == "baseline"]
    views = []
    for r in configs:
        if r["view"] not in views:
            views.append(r["view"])
    resolutions = []
    for r in configs:
        if r["resolution"] not in resolutions:
            resolutions.append(r["resolution"])
    formats = ["rgba8", "rgba16f", "rgba32f"]
    filters = ["nearest", "linear", "mip-1", "mip-2", "trilinear"]
    by = defaultdict(list)
    for r in configs:
        by[(r["resolution"], r["format"], r["filter"])].append(r)
    out = [f"### {meta['file']} ({meta['triangles']} triangles, {meta['size']}² px, {meta['adapter']})", ""]
    base = {b["view"]: b for b in baselines}
    if base:
        out.append("UV-texture baseline at the image size vs its own 4×4 supersampled render (the floor every "
                   "configuration is held to): " + ", ".join(
                       f"{v} {fmt(mean([b['psnr_db'] for b in baselines if b['view'] == v]))} dB"
                       for v in views) + f"; {baselines[0]['gpu_bytes']:,} GPU bytes.")
        out.append("")
    # PSNR by resolution × format, linear filter, per view.
    out.append("PSNR (dB) with the **linear** filter, by resolution and format, per view "
               "(samples = level 0; bytes = GPU bytes of the RGBA8 mesh):")
    out.append("")
    out.append("| resolution | samples | GPU bytes (rgba8) | " + " | ".join(
        f"{v} {f}" for v in views for f in ["8", "16f", "32f"]) + " |")
    out.append("|---" * (3 + 3 * len(views)) + "|")
    for res in resolutions:
        cells = []
        for v in views:
            for f in formats:
                rs = [r for r in by[(res, f, "linear")] if r["view"] == v]
                cells.append(fmt(mean([r["psnr_db"] for r in rs])))
        any_row = by[(res, "rgba8", "linear")][0]
        out.append(f"| {res} | {any_row['samples']:,} | {any_row['gpu_bytes']:,} | " + " | ".join(cells) + " |")
    out.append("")
    # PSNR by filter × view at RGBA8, for every resolution.
    out.append("PSNR (dB) by **filter** and view, RGBA8 (pixels per face of each view in the header):")
    out.append("")
    ppf = {v: mean([r["pixels_per_face"] for r in configs if r["view"] == v]) for v in views}
    out.append("| resolution | filter | " + " | ".join(f"{v} ({fmt(ppf[v], 2)} px/face)" for v in views) + " |")
    out.append("|---" * (2 + len(views)) + "|")
    for res in resolutions:
        for flt in filters:
            rs = by[(res, "rgba8", flt)]
            cells = [fmt(mean([r["psnr_db"] for r in rs if r["view"] == v])) for v in views]
            out.append(f"| {res} | {flt} | " + " | ".join(cells) + " |")
    out.append("")
    # Frame ratios and max error.
    out.append("Frame time / UV baseline (median of the interleaved rounds, mean over views), RGBA8, and the "
               "largest error in 8-bit steps (worst view) at the linear filter; pack seconds; dab samples/s:")
    out.append("")
    out.append("| resolution | " + " | ".join(filters) + " | max err (linear) | pack s (rgba8) | dab samples/s |")
    out.append("|---" * (4 + len(filters)) + "|")
    for res in resolutions:
        cells = [fmt(mean([r["frame_ratio"] for r in by[(res, "rgba8", flt)]]), 2) for flt in filters]
        lin = by[(res, "rgba8", "linear")]
        worst = max(r["max_error_steps"] for r in lin)
        dab = lin[0].get("dab_samples_per_second")
        out.append(f"| {res} | " + " | ".join(cells) +
                   f" | {worst} | {lin[0]['pack_seconds']:.4f} | {fmt(dab / 1e6 if dab else None, 2)} M |")
    out.append("")
    seams = [r for r in rows if r["kind"] == "seam"]
    if seams:
        out.append("Seam jumps across mixed-resolution edges (RGBA32F, CPU reference sampler, largest jump over "
                   "33 points per edge, colour units 0..1; trilinear at level + 0.5):")
        out.append("")
        levels = sorted({r["level"] for r in seams})
        out.append("| resolution | mixed edges | filter | " + " | ".join(f"L{l}" for l in levels) + " |")
        out.append("|---" * (3 + len(levels)) + "|")
        groups = []
        for r in seams:
            if (r["resolution"], r["filter"]) not in groups:
                groups.append((r["resolution"], r["filter"]))
        for res, flt in groups:
            rs = {r["level"]: r for r in seams if r["resolution"] == res and r["filter"] == flt}
            edges = next(iter(rs.values()))["mixed_edges"]
            cells = [("%.2g" % rs[l]["max_jump"]) if l in rs else "" for l in levels]
            out.append(f"| {res} | {edges} | {flt} | " + " | ".join(cells) + " |")
        out.append("")
    bvh = [r for r in rows if r["kind"] == "bvh"]
    if bvh:
        out.append("BVH presets (build, pick latency per ray, picks equal to brute force):")
        out.append("")
        out.append("| preset | build ms | pick µs (median) | agree / picks |")
        out.append("|---|---|---|---|")
        for r in bvh:
            out.append(f"| {r['preset']} | {r['build_seconds'] * 1e3:.3f} | {r['pick_seconds_median'] * 1e6:.2f} | "
                       f"{r['agree_with_brute_force']} / {r['picks']} |")
        out.append("")
    return "\n".join(out)


if __name__ == "__main__":
    print("\n\n".join(summarise(p) for p in sys.argv[1:]))
