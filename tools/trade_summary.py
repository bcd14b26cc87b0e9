#!/usr/bin/env python3
"""Markdown tables from `meshpaint bench trade` JSONL files (docs/TRADE.md).

    tools/trade_summary.py docs/trade/duck.jsonl [more.jsonl ...]

Per file: mesh colors and Mesh Color Textures side by side (same resolution, same filter,
same format: PSNR per view, frame ratio, GPU bytes, MCT bytes over mesh-colors bytes), PSNR by
resolution and format (linear filter), PSNR by filter and view, frame ratios of every filter
of both representations, pack and MCT build times, the seam jumps of both representations and
the BVH presets. Rows written before the representation axis count as mesh colors.
"""
import json
import math
import sys
from collections import defaultdict

FORMATS = ["rgba8", "rgba16f", "rgba32f"]
SHORT_FORMAT = {"rgba8": "8", "rgba16f": "16f", "rgba32f": "32f"}
FILTERS = ["nearest", "linear", "mip-1", "mip-2", "trilinear"]
MCT_FILTERS = ["linear", "mip-1", "mip-2", "trilinear"]
MC, MCT = "mesh-colors", "mct"


def mean(values):
    values = [v for v in values if v is not None]
    return sum(values) / len(values) if values else None


def fmt(value, digits=1):
    return "–" if value is None else f"{value:.{digits}f}"


def representation(row):
    return row.get("representation", MC)


def ordered(values):
    out = []
    for v in values:
        if v not in out:
            out.append(v)
    return out


class Rows:
    """The rows of one file, indexed."""

    def __init__(self, path):
        self.rows = [json.loads(line) for line in open(path) if line.strip()]
        self.meta = next(r for r in self.rows if r["kind"] == "meta")
        self.configs = [r for r in self.rows if r["kind"] == "config"]
        self.baselines = [r for r in self.rows if r["kind"] == "baseline"]
        self.views = ordered(r["view"] for r in self.configs)
        self.resolutions = ordered(r["resolution"] for r in self.configs)
        self.formats = [f for f in FORMATS if any(r["format"] == f for r in self.configs)]
        # The format of the side-by-side tables: RGBA8 when measured (formats agree on PSNR).
        self.main_format = self.formats[0] if self.formats else "rgba8"
        self.by = defaultdict(list)
        for r in self.configs:
            self.by[(representation(r), r["resolution"], r["format"], r["filter"])].append(r)
        self.has_mct = any(representation(r) == MCT for r in self.configs)

    def get(self, rep, res, fmt_, flt, view=None):
        rs = self.by[(rep, res, fmt_, flt)]
        return [r for r in rs if view is None or r["view"] == view]

    def psnr(self, rep, res, fmt_, flt, view):
        return mean([r["psnr_db"] for r in self.get(rep, res, fmt_, flt, view)])

    def ratio(self, rep, res, fmt_, flt):
        return mean([r["frame_ratio"] for r in self.get(rep, res, fmt_, flt)])


def header(t):
    meta = t.meta
    out = [f"### {meta['file']} ({meta['triangles']} triangles, {meta['size']}² px, {meta['adapter']})", ""]
    if t.baselines:
        out.append("UV-texture baseline at the image size vs its own 4×4 supersampled render (the floor every "
                   "configuration is held to): " + ", ".join(
                       f"{v} {fmt(mean([b['psnr_db'] for b in t.baselines if b['view'] == v]))} dB"
                       for v in t.views) + f"; {t.baselines[0]['gpu_bytes']:,} GPU bytes.")
        out.append("")
    skipped = [r for r in t.rows if r["kind"] == "skipped"]
    for r in skipped:
        out.append(f"MCT skipped at {r['resolution']} {r['format']}: {r['reason']}")
    if skipped:
        out.append("")
    return out


def side_by_side(t):
    """Mesh colors and MCT at the same R, filter and format."""
    f = t.main_format
    out = [f"**Mesh colors vs MCT**, {f}, same pack, same reference, same pixels: PSNR (dB) per view as "
           "mesh colors / MCT, frame time / UV baseline (mean over views) mesh colors / MCT, GPU bytes in total "
           "(geometry + colours) mesh colors / MCT, and MCT's atlas + records over the packed face records + "
           "colours:", ""]
    out.append("| R | filter | " + " | ".join(t.views) + " | frame ratio | GPU bytes | MCT / MC bytes |")
    out.append("|---" * (5 + len(t.views)) + "|")
    for res in t.resolutions:
        for flt in MCT_FILTERS:
            mc, mct = t.get(MC, res, f, flt), t.get(MCT, res, f, flt)
            if not mc or not mct:
                continue
            cells = [f"{fmt(t.psnr(MC, res, f, flt, v))} / {fmt(t.psnr(MCT, res, f, flt, v))}" for v in t.views]
            out.append(f"| {res} | {flt} | " + " | ".join(cells) +
                       f" | {fmt(t.ratio(MC, res, f, flt), 2)} / {fmt(t.ratio(MCT, res, f, flt), 2)}"
                       f" | {mc[0]['gpu_bytes']:,} / {mct[0]['gpu_bytes']:,}"
                       f" | {mct[0]['mct_bytes_over_mesh_colors']:.3f} |")
    out.append("")
    return out


def geomean(xs):
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else None


def paired_frames(t):
    """MCT frame time over mesh colors' at the same R, format, filter and view (the two were
    timed in the same interleaved rounds, so the pair cancels part of the machine noise)."""
    out = ["MCT frame time / mesh-colors frame time, paired (same R, format, filter and view, timed in the same "
           "interleaved rounds): geometric mean over the pairs (every R and format) per view, then over all views "
           "with the range of single pairs; below 1 = MCT faster. Median baseline frame per view in the header:", ""]
    base = {v: mean([r["baseline_frame_ms"] for r in t.configs if r["view"] == v]) for v in t.views}
    out.append("| filter | " + " | ".join(f"{v} ({fmt(base[v], 2)} ms)" for v in t.views) +
               " | all views | range |")
    out.append("|---" * (3 + len(t.views)) + "|")
    for flt in MCT_FILTERS:
        per_view = {v: [] for v in t.views}
        for res in t.resolutions:
            for f in t.formats:
                for v in t.views:
                    mc, mct = t.get(MC, res, f, flt, v), t.get(MCT, res, f, flt, v)
                    if mc and mct:
                        per_view[v].append(mct[0]["frame_ms"] / mc[0]["frame_ms"])
        pairs = [x for v in t.views for x in per_view[v]]
        if not pairs:
            continue
        out.append(f"| {flt} | " + " | ".join(fmt(geomean(per_view[v]), 2) for v in t.views) +
                   f" | {geomean(pairs):.2f} | {min(pairs):.2f}–{max(pairs):.2f} |")
    out.append("")
    return out


def pick(t):
    """The figures `Which representation to pick` (docs/TRADE.md) rests on, per resolution."""
    seams = [r for r in t.rows if r["kind"] == "seam" and representation(r) == MCT]
    out = ["Per resolution, mesh colors / MCT: PSNR (dB, rgba8) with linear near and mid and trilinear far and tiny; "
           "MCT frame time over mesh colors' paired (same R, format, filter and view, timed in the same interleaved "
           "rounds; geometric mean over the three formats and the views "
           "named); GPU bytes in total (rgba8); MCT atlas + records over packed face records + colours (rgba8 / "
           "rgba16f); MCT seams, largest and largest mean jump over levels and filters in 8-bit steps (linear × 255), "
           "rgba8, and largest in rgba16f (mesh colors: 0 at every R in linear and trilinear):", ""]
    out.append("| R | near lin | mid lin | far tri | tiny tri | frame lin near+mid | frame tri near+mid | "
               "frame tri far+tiny | GPU bytes | MCT / MC bytes 8 / 16f | seam 8 max / mean | seam 16f max |")
    out.append("|---" * 12 + "|")
    for res in t.resolutions:
        if not t.get(MCT, res, "rgba8", "linear"):
            continue
        cell = lambda flt, v: f"{fmt(t.psnr(MC, res, 'rgba8', flt, v))} / {fmt(t.psnr(MCT, res, 'rgba8', flt, v))}"

        def paired(flt, views):
            xs = [a["frame_ms"] / b["frame_ms"] for f in t.formats for v in views
                  for a, b in zip(t.get(MCT, res, f, flt, v), t.get(MC, res, f, flt, v))]
            return fmt(geomean(xs), 2)

        mc, mct = t.get(MC, res, "rgba8", "linear")[0], t.get(MCT, res, "rgba8", "linear")[0]
        mct16 = t.get(MCT, res, "rgba16f", "linear")
        s8 = [r for r in seams if r["resolution"] == res and r["format"] == "rgba8"]
        s16 = [r for r in seams if r["resolution"] == res and r["format"] == "rgba16f"]
        seam8 = (f"{max(r['max_jump'] for r in s8) * 255:.0f} / {max(r['mean_jump'] for r in s8) * 255:.2f}"
                 if s8 else "–")
        seam16 = f"{max(r['max_jump'] for r in s16) * 255:.2f}" if s16 else "–"
        ratio16 = f"{mct16[0]['mct_bytes_over_mesh_colors']:.2f}" if mct16 else "–"
        out.append(f"| {res} | {cell('linear', 'near')} | {cell('linear', 'mid')} | {cell('trilinear', 'far')} | "
                   f"{cell('trilinear', 'tiny')} | {paired('linear', ['near', 'mid'])} | "
                   f"{paired('trilinear', ['near', 'mid'])} | {paired('trilinear', ['far', 'tiny'])} | "
                   f"{mc['gpu_bytes']:,} / {mct['gpu_bytes']:,} | {mct['mct_bytes_over_mesh_colors']:.2f} / {ratio16} | "
                   f"{seam8} | {seam16} |")
    out.append("")
    return out


def best_of_each(t):
    """Per R and view: the best PSNR each representation reaches over its filters."""
    f = t.main_format
    out = [f"Best PSNR (dB) over the filters, per view, {f}: mesh colors (its filters incl. nearest) / MCT "
           "(linear, mip-1, mip-2, trilinear), with the filter that reaches it:", ""]
    out.append("| R | " + " | ".join(t.views) + " |")
    out.append("|---" * (1 + len(t.views)) + "|")
    short = {"nearest": "near", "linear": "lin", "trilinear": "tri"}
    for res in t.resolutions:
        cells = []
        for v in t.views:
            parts = []
            for rep, filters in ((MC, FILTERS), (MCT, MCT_FILTERS)):
                scored = [(t.psnr(rep, res, f, flt, v), flt) for flt in filters]
                scored = [s for s in scored if s[0] is not None]
                if scored:
                    p, flt = max(scored)
                    parts.append(f"{p:.1f} {short.get(flt, flt)}")
                else:
                    parts.append("–")
            cells.append(" / ".join(parts))
        out.append(f"| {res} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def by_format(t):
    out = ["PSNR (dB) with mesh colors' **linear** filter, by resolution and format, per view "
           f"(samples = level 0; bytes = GPU bytes of the {t.main_format} mesh):", ""]
    out.append("| resolution | samples | GPU bytes | " + " | ".join(
        f"{v} {SHORT_FORMAT[f]}" for v in t.views for f in t.formats) + " |")
    out.append("|---" * (3 + len(t.formats) * len(t.views)) + "|")
    for res in t.resolutions:
        cells = [fmt(t.psnr(MC, res, f, "linear", v)) for v in t.views for f in t.formats]
        any_row = t.get(MC, res, t.main_format, "linear")[0]
        out.append(f"| {res} | {any_row['samples']:,} | {any_row['gpu_bytes']:,} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def by_filter(t):
    f = t.main_format
    ppf = {v: mean([r["pixels_per_face"] for r in t.configs if r["view"] == v]) for v in t.views}
    out = [f"PSNR (dB) by **filter** and view, {f}, both representations (pixels per face of each view in "
           "the header):", ""]
    out.append("| resolution | representation | filter | " + " | ".join(
        f"{v} ({fmt(ppf[v], 2)} px/face)" for v in t.views) + " |")
    out.append("|---" * (3 + len(t.views)) + "|")
    for res in t.resolutions:
        for rep, filters in ((MC, FILTERS), (MCT, MCT_FILTERS)):
            for flt in filters:
                if not t.get(rep, res, f, flt):
                    continue
                cells = [fmt(t.psnr(rep, res, f, flt, v)) for v in t.views]
                out.append(f"| {res} | {rep} | {flt} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def costs(t):
    f = t.main_format
    cols = [(MC, flt) for flt in FILTERS] + ([(MCT, flt) for flt in MCT_FILTERS] if t.has_mct else [])
    out = [f"Frame time / UV baseline (median of the interleaved rounds, mean over views), {f}; the largest "
           "error in 8-bit steps (worst view) at the linear filter, mesh colors / MCT; pack and MCT build seconds "
           "(best of 3); dab samples/s:", ""]
    names = [("" if rep == MC else "MCT ") + flt for rep, flt in cols]
    out.append("| resolution | " + " | ".join(names) + " | max err (linear) | pack s | MCT build s | dab samples/s |")
    out.append("|---" * (5 + len(cols)) + "|")
    for res in t.resolutions:
        cells = [fmt(t.ratio(rep, res, f, flt), 2) for rep, flt in cols]
        lin = t.get(MC, res, f, "linear")
        mct_lin = t.get(MCT, res, f, "linear")
        worst = max(r["max_error_steps"] for r in lin)
        worst_mct = max(r["max_error_steps"] for r in mct_lin) if mct_lin else None
        dab = lin[0].get("dab_samples_per_second")
        build = mct_lin[0]["mct_build_seconds"] if mct_lin else None
        out.append(f"| {res} | " + " | ".join(cells) +
                   f" | {worst} / {'–' if worst_mct is None else worst_mct} | {lin[0]['pack_seconds']:.4f}"
                   f" | {fmt(build, 4)} | {fmt(dab / 1e6 if dab else None, 2)} M |")
    out.append("")
    return out


def seams(t):
    rows = [r for r in t.rows if r["kind"] == "seam"]
    if not rows:
        return []
    ppe = sorted({r.get("points_per_edge", 33) for r in rows})
    out = ["Seams per resolution, in 8-bit steps (colour units × 255): the largest jump between the two sides of an "
           "edge over every level and filter, and the largest mean jump over the points of one level and filter "
           "(mesh colors: linear and trilinear, CPU reference sampler, RGBA32F; MCT: CPU evaluation of the hardware "
           "filter, per format):", ""]
    compact = ordered((r["resolution"], representation(r), r.get("format", "rgba32f")) for r in rows)
    by_res = ordered(c[0] for c in compact)
    columns = ordered((c[1], c[2]) for c in compact)
    out.append("| resolution | edges (mixed) | " + " | ".join(f"{rep} {f} max / mean" for rep, f in columns) + " |")
    out.append("|---" * (2 + len(columns)) + "|")
    for res in by_res:
        cells = []
        for rep, f in columns:
            rs = [r for r in rows if (r["resolution"], representation(r), r.get("format", "rgba32f")) == (res, rep, f)
                  and r["filter"] != "nearest"]
            cells.append(f"{max(r['max_jump'] for r in rs) * 255:.2g} / {max(r['mean_jump'] for r in rs) * 255:.2g}"
                         if rs else "–")
        first = next(r for r in rows if r["resolution"] == res)
        out.append(f"| {res} | {first.get('edges', first['mixed_edges'])} ({first['mixed_edges']}) | " +
                   " | ".join(cells) + " |")
    out.append("")
    out += [f"Seam jumps per level: the largest difference between the two sides of an edge over {'/'.join(map(str, ppe))} "
            "points per edge (t = k/n, n = max(32, 2 · largest R)), colour units 0..1 (trilinear at level + 0.5). "
            "`edges` = edges compared (mixed = faces of different R):", ""]
    levels = sorted({r["level"] for r in rows})
    out.append("| resolution | edges (mixed) | representation | format | filter | " +
               " | ".join(f"L{l}" for l in levels) + " |")
    out.append("|---" * (5 + len(levels)) + "|")
    groups = ordered((r["resolution"], representation(r), r.get("format", "rgba32f"), r["filter"]) for r in rows)
    for res, rep, f, flt in groups:
        rs = {r["level"]: r for r in rows if (r["resolution"], representation(r), r.get("format", "rgba32f"),
                                              r["filter"]) == (res, rep, f, flt)}
        first = next(iter(rs.values()))
        edges = f"{first.get('edges', first['mixed_edges'])} ({first['mixed_edges']})"
        cells = [("%.2g" % rs[l]["max_jump"]) if l in rs else "" for l in levels]
        out.append(f"| {res} | {edges} | {rep} | {f} | {flt} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def bvh(t):
    rows = [r for r in t.rows if r["kind"] == "bvh"]
    if not rows:
        return []
    out = ["BVH presets (build, pick latency per ray, picks equal to brute force):", ""]
    out.append("| preset | build ms | pick µs (median) | agree / picks |")
    out.append("|---|---|---|---|")
    for r in rows:
        out.append(f"| {r['preset']} | {r['build_seconds'] * 1e3:.3f} | {r['pick_seconds_median'] * 1e6:.2f} | "
                   f"{r['agree_with_brute_force']} / {r['picks']} |")
    out.append("")
    return out


def summarise(path):
    t = Rows(path)
    out = header(t)
    if t.has_mct:
        out += pick(t) + side_by_side(t) + paired_frames(t) + best_of_each(t)
    out += by_format(t) + by_filter(t) + costs(t) + seams(t) + bvh(t)
    return "\n".join(out)


if __name__ == "__main__":
    print("\n\n".join(summarise(p) for p in sys.argv[1:]))
