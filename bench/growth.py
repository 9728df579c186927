#!/usr/bin/env python3
"""Time per guided-projection iteration against the number of unknowns, for every model that
iterates at several sizes (issue 17 item 3), on one core: a log–log plot (PNG) and the fitted
exponents.

Series (medians of the benches' repetitions, `iteration_ms` and `unknowns` counters):
  strip            bench/strip_iteration      StripIteration/cholmod/{10,100,1000,1500} spans
  composite        bench/composite_iteration  CompositeSheet/*/nodev/auto (parallel-crease sheets)
  composite + dev  bench/composite_iteration  CompositeSheet/*/dev/auto (development managed)
  comp. + dev. apart                          CompositeSheet/*/dev/alternating (DevelopmentSolve::Alternating)
  … with normal splines                       CompositeSheet/*/{nodev,dev}/splines (CompositeOptions::normalSplines)
  quad mesh        bench/quad_mesh_iteration  QuadMeshApprox/preset/* (factorization reused)
  quad mesh, factorizing every step           QuadMeshApprox/preset_factorize/*
Quasi strips and conical strips are solved at one size each (their benches time one preset), spline
surfaces are quad meshes with a control net (bench/spline_surface): not series here.

The exponent is the least-squares slope of log(ms per iteration) against log(unknowns) over the
sizes from 10 000 unknowns on (where the asymptotic cost shows; over all sizes too, for reference).
Issue 17 asks that no model grow faster than n^1.5.

Usage: bench/growth.py [--build build] [--out docs/growth.png] [--json results.json] [--quick]
  --quick     the two smallest quad-mesh sizes only (a check of the script, not a measurement)
  --from-json read earlier results (written by --json) instead of running the benches
  --only      with --from-json: run again the series whose labels start with one of these
              (comma-separated, e.g. "composite,comp."), keep the others as read
The benches run under `taskset -c 0` with OMP_NUM_THREADS=1 (one core), one after the other.
The PNG is the SVG drawn here, rendered by Chromium headless (/usr/bin/chromium).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SERIES = [
    # (label, binary, filter, name part that must match, colour)
    ("strip", "strip_iteration", "StripIteration/cholmod/", "StripIteration/cholmod/", "#1f77b4"),
    ("composite", "composite_iteration", "CompositeSheet/.*/nodev/auto/", "/nodev/auto/", "#2ca02c"),
    ("composite + development", "composite_iteration", "CompositeSheet/.*/dev/auto/", "/dev/auto/", "#98df8a"),
    ("comp. + dev. apart (its factor reused)", "composite_iteration", "CompositeSheet/.*/dev/alternating/",
     "/dev/alternating/", "#17becf"),
    ("composite, spline normals", "composite_iteration", "CompositeSheet/.*/nodev/splines/", "/nodev/splines/", "#9467bd"),
    ("comp. + dev., spline normals", "composite_iteration", "CompositeSheet/.*/dev/splines/", "/dev/splines/",
     "#c5b0d5"),
    ("quad mesh (reuse)", "quad_mesh_iteration", "QuadMeshApprox/preset/", "QuadMeshApprox/preset/", "#d62728"),
    ("quad mesh (factorize every step)", "quad_mesh_iteration", "QuadMeshApprox/preset_factorize/",
     "QuadMeshApprox/preset_factorize/", "#ff9896"),
]


def run_bench(build, binary, flt, quick):
    exe = os.path.join(build, "bench", binary)
    if not os.access(exe, os.X_OK):
        sys.exit(f"growth.py: {exe} not built (cmake --build {build} --target {binary})")
    if quick and binary == "quad_mesh_iteration":
        flt = flt + "(45|90)/"
    cmd = ["taskset", "-c", "0", exe, f"--benchmark_filter={flt}", "--benchmark_format=json"]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    return json.loads(out)["benchmarks"]


def points_of(benchmarks, part):
    """(unknowns, ms per iteration) per size: the median aggregate where there are repetitions."""
    by_name = {}
    for b in benchmarks:
        if part not in b["name"] or "unknowns" not in b or "iteration_ms" not in b:
            continue
        base = b.get("run_name", b["name"])
        agg = b.get("aggregate_name")
        if agg not in (None, "", "median"):
            continue
        if agg == "median" or base not in by_name:
            by_name[base] = (float(b["unknowns"]), float(b["iteration_ms"]))
    return sorted(by_name.values())


def slope(points):
    if len(points) < 2:
        return float("nan")
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def svg_plot(results, width=900, height=620):
    left, right, top, bottom = 90, 300, 40, 70
    allp = [p for r in results for p in r["points"]]
    x0 = 10 ** math.floor(math.log10(min(n for n, _ in allp)))
    x1 = 10 ** math.ceil(math.log10(max(n for n, _ in allp)))
    y0 = 10 ** math.floor(math.log10(min(t for _, t in allp)))
    y1 = 10 ** math.ceil(math.log10(max(t for _, t in allp)))
    pw, ph = width - left - right, height - top - bottom

    def X(n):
        return left + pw * (math.log10(n) - math.log10(x0)) / (math.log10(x1) - math.log10(x0))

    def Y(t):
        return top + ph * (1 - (math.log10(t) - math.log10(y0)) / (math.log10(y1) - math.log10(y0)))

    s = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
         f'font-family="DejaVu Sans, sans-serif" font-size="13">',
         f'<rect width="{width}" height="{height}" fill="white"/>']
    for k in range(int(math.log10(x0)), int(math.log10(x1)) + 1):
        x = X(10 ** k)
        s.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{top + ph}" stroke="#ddd"/>')
        s.append(f'<text x="{x:.1f}" y="{top + ph + 20}" text-anchor="middle">10<tspan dy="-6" font-size="10">{k}</tspan></text>')
    for k in range(int(math.log10(y0)), int(math.log10(y1)) + 1):
        y = Y(10 ** k)
        s.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + pw}" y2="{y:.1f}" stroke="#ddd"/>')
        label = f"{10 ** k:g}"
        s.append(f'<text x="{left - 8}" y="{y + 4:.1f}" text-anchor="end">{label}</text>')
    s.append(f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>')
    s.append(f'<text x="{left + pw / 2}" y="{height - 25}" text-anchor="middle">unknowns</text>')
    s.append(f'<text transform="translate(25,{top + ph / 2}) rotate(-90)" text-anchor="middle">ms per iteration (one core)</text>')
    s.append(f'<text x="{left}" y="24" font-size="15">Time per guided-projection iteration against unknowns</text>')
    # n^1.5 reference through the first point of the largest series, dashed.
    ref = max(results, key=lambda r: r["points"][-1][0])["points"][-1]
    a = ref[1] / ref[0] ** 1.5
    nA, nB = x0, x1
    tA, tB = a * nA ** 1.5, a * nB ** 1.5
    s.append(f'<line x1="{X(nA):.1f}" y1="{Y(tA):.1f}" x2="{X(nB):.1f}" y2="{Y(tB):.1f}" stroke="#888" '
             f'stroke-dasharray="6 5" clip-path="url(#plot)"/>')
    s.insert(2, f'<defs><clipPath id="plot"><rect x="{left}" y="{top}" width="{pw}" height="{ph}"/></clipPath></defs>')
    ly = top + 10
    for r in results:
        pts = " ".join(f"{X(n):.1f},{Y(t):.1f}" for n, t in r["points"])
        s.append(f'<polyline points="{pts}" fill="none" stroke="{r["colour"]}" stroke-width="2.5"/>')
        for n, t in r["points"]:
            s.append(f'<circle cx="{X(n):.1f}" cy="{Y(t):.1f}" r="4" fill="{r["colour"]}"/>')
        s.append(f'<rect x="{left + pw + 15}" y="{ly}" width="14" height="14" fill="{r["colour"]}"/>')
        s.append(f'<text x="{left + pw + 35}" y="{ly + 12}">{r["label"]}</text>')
        e = r["exponent_large"] if not math.isnan(r["exponent_large"]) else r["exponent_all"]
        s.append(f'<text x="{left + pw + 35}" y="{ly + 28}" font-size="12" fill="#444">n^{e:.2f}</text>')
        ly += 46
    s.append(f'<line x1="{left + pw + 15}" y1="{ly + 7}" x2="{left + pw + 29}" y2="{ly + 7}" stroke="#888" stroke-dasharray="4 3"/>')
    s.append(f'<text x="{left + pw + 35}" y="{ly + 12}">n^1.5 (the limit)</text>')
    s.append("</svg>")
    return "\n".join(s)


def render_png(svg_text, out, width=900, height=620):
    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    with tempfile.TemporaryDirectory() as d:
        page = os.path.join(d, "plot.html")
        with open(page, "w") as f:
            f.write(f'<!doctype html><html><body style="margin:0">{svg_text}</body></html>')
        subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                        f"--window-size={width},{height}", f"--screenshot={os.path.abspath(out)}", "file://" + page],
                       check=True, capture_output=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "growth.png"))
    ap.add_argument("--json")
    ap.add_argument("--from-json")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only")
    args = ap.parse_args()
    only = [p for p in (args.only or "").split(",") if p]
    if only and not args.from_json:
        sys.exit("growth.py: --only needs --from-json (the series it keeps)")

    kept = []
    if args.from_json:
        with open(args.from_json) as f:
            kept = json.load(f)
    if args.from_json and not only:
        results = kept
    else:
        cache = {}
        results = []
        for label, binary, flt, part, colour in SERIES:
            if only and not any(label.startswith(p) for p in only):
                results.extend(r for r in kept if r["label"] == label)
                continue
            key = (binary, flt)
            if key not in cache:
                print(f"growth.py: {binary} {flt} …", file=sys.stderr)
                cache[key] = run_bench(args.build, binary, flt, args.quick)
            pts = points_of(cache[key], part)
            if not pts:
                continue
            large = [p for p in pts if p[0] >= 10000]
            results.append({"label": label, "colour": colour, "points": pts,
                            "exponent_all": slope(pts), "exponent_large": slope(large)})
        if args.json:
            with open(args.json, "w") as f:
                json.dump(results, f, indent=1)

    print("| model | unknowns | ms per iteration | exponent (≥ 10 000 unknowns) | exponent (all) |")
    print("|---|---|---|---|---|")
    for r in results:
        sizes = ", ".join(f"{int(n):,}".replace(",", " ") for n, _ in r["points"])
        times = ", ".join(f"{t:.3g}" for _, t in r["points"])
        el = "–" if math.isnan(r["exponent_large"]) else f"{r['exponent_large']:.2f}"
        print(f"| {r['label']} | {sizes} | {times} | {el} | {r['exponent_all']:.2f} |")
    svg = svg_plot(results)
    render_png(svg, args.out)
    print(f"growth.py: wrote {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
