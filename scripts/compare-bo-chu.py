#!/usr/bin/env python3
"""Bo et al. (quasi_strip) against Chu et al. (conical_strip) on the same curve pairs.

Runs `devsurf solve` on examples/quasi-strip-*.json and examples/conical-strip-*.json (the same
curve pairs, written by scripts/issue6-presets.py) and prints a markdown table built from the
reports' metrics. Times are the median of --runs runs of the whole solve as the report gives it
(time_ms: model build, solve, metrics).

usage: scripts/compare-bo-chu.py [--devsurf build/server/devsurf] [--runs 3] [--out docs/comparison-bo-chu.md]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAIRS = ["hull", "brim", "twisted"]


def solve(devsurf, scene, runs):
    reports = []
    for _ in range(runs):
        out = subprocess.run([devsurf, "solve", scene], check=True, capture_output=True, text=True).stdout
        reports.append(json.loads(out))
    report = reports[-1]
    report["time_ms"] = statistics.median(r["time_ms"] for r in reports)
    return report


def fmt(x, digits=3):
    if x == 0:
        return "0"
    if abs(x) >= 1e-2 and abs(x) < 1e4:
        return f"{x:.{digits}g}" if abs(x) < 1 else f"{x:.{max(1, digits - 1)}f}".rstrip("0").rstrip(".")
    return f"{x:.2e}"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--devsurf", default=os.path.join(ROOT, "build", "server", "devsurf"))
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--out", default=None, help="write the markdown here instead of stdout")
    args = parser.parse_args()

    lines = [
        "| curve pair | method | max warp (°) | mean warp (°) | max warp, 1000 rulings (°) | normal variation (eq. 7) | max normal jump (rad) | patches n3/n4 | deviation from input curves | time (ms) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for pair in PAIRS:
        bo_scene = os.path.join(ROOT, "examples", f"quasi-strip-{pair}.json")
        chu_scene = os.path.join(ROOT, "examples", f"conical-strip-{pair}.json")
        units = json.load(open(bo_scene)).get("units", "mm")
        bo = solve(args.devsurf, bo_scene, args.runs)
        m = bo["metrics"]
        lines.append(
            f"| {pair} ({units}) | Bo: quasi_strip, σ degree 2 × 50, K = 100, L-BFGS | {fmt(m['warp_angle_max_deg'])} | "
            f"{fmt(m['warp_angle_mean_deg'])} | {fmt(m['warp_angle_max_deg_dense'])} | — | — | — | "
            f"{fmt(m['deviation_max'])} {units} | {fmt(bo['time_ms'], 3)} |")
        chu = solve(args.devsurf, chu_scene, args.runs)
        m = chu["metrics"]
        d = json.load(open(chu_scene))["model"]
        params = f"Np/Nq {d['np']}/{d['nq']}, H3 {d['h3']}, H4 {d['h4']}, ra {d['ra']}"
        lines.append(
            f"| | Chu: conical_strip greedy (G0, quadratic), {params} | 0 in every patch | 0 | 0 in every patch | "
            f"{fmt(m['greedy_normal_variation'])} | {fmt(m['greedy_normal_jump_max_rad'])} | "
            f"{int(m['greedy_n3'])}/{int(m['greedy_n4'])} | {fmt(m['greedy_deviation_max'])} {units} "
            f"(corners {fmt(m['greedy_corner_deviation_max'])}) | |")
        lines.append(
            f"| | Chu: after degree elevation + G1 adjustment (cubic) | 0 in every patch | 0 | 0 in every patch | "
            f"{fmt(m['normal_variation'])} | {fmt(m['normal_jump_max_rad'])} | {int(m['n3'])}/{int(m['n4'])} | "
            f"{fmt(m['deviation_max'])} {units} (corners {fmt(m['corner_deviation_max'])}) | {fmt(chu['time_ms'], 3)} |")
    table = "\n".join(lines) + "\n"
    if args.out:
        with open(args.out, "w") as f:
            f.write(table)
    else:
        sys.stdout.write(table)


if __name__ == "__main__":
    main()
