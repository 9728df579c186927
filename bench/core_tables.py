#!/usr/bin/env python3
"""Per-iteration phases of every model at its largest benchmarked size, on one core and on two.

Runs the Google Benchmark binaries of build/bench (strip_iteration, composite_iteration,
quad_mesh_iteration) under `taskset -c 0` and under `taskset -c 0,1` and prints one Markdown table
per model: assembly, factorization, solve and the whole iteration (medians, ms), with the paper's
figure beside it (Tang et al. 2016 Fig. 17; Jiang et al. 2020 Fig. 22) and the time when issue 17
was opened.

What a second core does: the assembler accumulates JᵀJ on two threads once an assembly has
NormalEquations::kParallelAssemblyProducts products (it chooses from the process's affinity);
CHOLMOD runs on one thread by design (LinearSolver.cpp: its OpenMP regions and the serial OpenBLAS
Debian ships), so factorization and solve do not change.

Usage: bench/core_tables.py [build/bench] [--only strip|composite|quad] [--json out.json]
Takes 5–10 minutes. Run it on an otherwise idle machine; nothing else should be compiling.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

# (model, binary, benchmark filter, label, time per iteration when issue 17 was opened (ms) or None)
CASES = [
    ("strip", "strip_iteration", "^StripIteration/cholmod/1500/", "strip, 1 500 spans, CHOLMOD", 7.7),
    ("strip", "strip_iteration", "^StripIteration/ldlt/1500/", "strip, 1 500 spans, LDLT", None),
    ("composite", "composite_iteration", "^CompositeSheet/40x40/nodev/auto/", "composite 40 × 40", 158.0),
    ("composite", "composite_iteration", "^CompositeSheet/40x40/dev/auto/",
     "composite 40 × 40 + development (coupled)", 405.0),
    ("composite", "composite_iteration", "^CompositeSheet/40x40/dev/alternating/",
     "composite 40 × 40 + development apart", None),
    ("quad", "quad_mesh_iteration", "^QuadMeshApprox/preset/224/", "quad mesh 224² (factorization reused)", None),
    ("quad", "quad_mesh_iteration", "^QuadMeshApprox/preset_factorize/224/",
     "quad mesh 224² (factorized every step)", None),
]

PAPER = {
    "strip": "Tang et al. Fig. 17: 39 648 variables, 800 ms per iteration (i5-3320M)",
    "composite": "Tang et al. Fig. 17: 39 648 variables, 800 ms per iteration (i5-3320M)",
    "quad": "Jiang et al. Fig. 22: 250 000 variables, 65.8–412 s for 10–20 iterations (3.3–41 s each)",
}

PHASES = ("assembly_ms", "factorization_ms", "solve_ms", "iteration_ms")


def run(binary, pattern, cores):
    """Median counters of the benchmarks matching `pattern`, run on the given CPU list."""
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as out:
        path = out.name
    env = dict(os.environ, OMP_NUM_THREADS="1" if cores == "0" else "2")
    cmd = ["taskset", "-c", cores, binary, f"--benchmark_filter={pattern}",
           f"--benchmark_out={path}", "--benchmark_out_format=json"]
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    with open(path) as f:
        data = json.load(f)
    os.unlink(path)
    rows = [b for b in data["benchmarks"] if b.get("aggregate_name") == "median"]
    if not rows:  # a single repetition reports no aggregates
        rows = [b for b in data["benchmarks"] if b.get("run_type") == "iteration"]
    if not rows:
        raise RuntimeError(f"{binary}: nothing matched {pattern}")
    for b in rows:
        if b.get("error_occurred"):
            raise RuntimeError(f"{binary} {b['name']}: {b.get('error_message')}")
    return rows[0]


def fmt(v):
    return f"{v:.1f}" if v >= 10 else f"{v:.2f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("bench_dir", nargs="?", default="build/bench")
    parser.add_argument("--only", choices=["strip", "composite", "quad"])
    parser.add_argument("--json", help="also write the measurements here")
    args = parser.parse_args()

    results = []
    for model, binary, pattern, label, before in CASES:
        if args.only and model != args.only:
            continue
        path = os.path.join(args.bench_dir, binary)
        if not os.access(path, os.X_OK):
            sys.exit(f"core_tables.py: {path} not found; build it with cmake --build build --target {binary}")
        one = run(path, pattern, "0")
        two = run(path, pattern, "0,1")
        results.append({"model": model, "label": label, "unknowns": int(one.get("unknowns", 0)),
                        "before_ms": before,
                        "one_core": {p: one.get(p) for p in PHASES},
                        "two_cores": {p: two.get(p) for p in PHASES}})
        print(f"measured {label}", file=sys.stderr)

    for model in ("strip", "composite", "quad"):
        rows = [r for r in results if r["model"] == model]
        if not rows:
            continue
        print(f"\n**{model}** — {PAPER[model]}\n")
        print("| model | unknowns | cores | assembly | factorization | solve | iteration | "
              "iteration ÷ factorization | when issue 17 was opened |")
        print("|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            for cores, key in (("1", "one_core"), ("2", "two_cores")):
                m = r[key]
                ratio = m["iteration_ms"] / m["factorization_ms"] if m["factorization_ms"] else float("nan")
                before = fmt(r["before_ms"]) if r["before_ms"] and cores == "1" else "–"
                unknowns = f"{r['unknowns']:,}".replace(",", " ")
                print(f"| {r['label']} | {unknowns} | {cores} | {fmt(m['assembly_ms'])} | "
                      f"{fmt(m['factorization_ms'])} | {fmt(m['solve_ms'])} | {fmt(m['iteration_ms'])} | "
                      f"{ratio:.2f} | {before} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
