#!/usr/bin/env python3
"""Solve time against unknowns for the obstacle solvers, and its fitted exponent (issue 15).

Runs `fem-forms solve membrane-radial --pair P --mesh-size N --json` for every pair and
mesh size asked for, keeps the best of --repeat runs of the solve (`seconds`: assembly
and every nested level) and of the peak memory (GNU time's maximum resident set size),
and fits `seconds ≈ c · n^p` by least squares on the logarithms, n the primal unknowns
((N−1)² interior vertices; the multipliers of p1-p0 are proportional to them, so the
exponent is the same counted with them). Issue 15 asks for p ≤ 1.1 from 10⁴ to at
least 4·10⁶ unknowns (N = 128 to 2048).

The page cache is part of the measurement: straight after a build the kernel holds most
of the free memory as cache, and the first large run pays seconds of system time
reclaiming it (`docs/multigrid.md`, "The whole process and p1-p0's memory"). The script
therefore runs the largest case once, unmeasured, before it measures. Needs no PETSc
(`benches/petsc_ex9.py` compares with PETSc). Usage, from the repository root:

    python3 benches/solve_exponent.py [--pairs p1-nodal,p1-p0] [--sizes 128,256,512,1024,2048]
                                      [--repeat 2] [--linear-solver auto]
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile


def timed(cmd):
    """stdout of `cmd` and its peak resident set in MB (GNU time when installed)."""
    gnu_time = "/usr/bin/time"
    if os.path.exists(gnu_time):
        full = [gnu_time, "-f", "%M"] + cmd
    else:
        full = cmd
    done = subprocess.run(full, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stderr}")
    peak = None
    if full is not cmd:
        match = re.search(r"(\d+)\s*$", done.stderr)
        peak = int(match.group(1)) / 1024 if match else None
    return done.stdout, peak


def solve(binary, pair, n, linear_solver, out):
    stdout, peak = timed([binary, "solve", "membrane-radial", "--pair", pair,
                          "--mesh-size", str(n), "--linear-solver", linear_solver,
                          "--json", "--out", out])
    report = json.loads(stdout)
    return report["seconds"], peak, report.get("linear_solver", "?")


def fit(points):
    """Least-squares slope and intercept of log t against log n."""
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    return slope, my - slope * mx


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", default="p1-nodal,p1-p0", help="comma-separated pairs")
    parser.add_argument("--sizes", default="128,256,512,1024,2048",
                        help="mesh sizes N (cells per side), comma-separated, at least two")
    parser.add_argument("--repeat", type=int, default=2, help="runs per case (best kept)")
    parser.add_argument("--linear-solver", default="auto", help="auto, direct or multigrid")
    parser.add_argument("--no-build", action="store_true",
                        help="use target/release/fem-forms as it is")
    args = parser.parse_args()
    pairs = args.pairs.split(",")
    sizes = sorted(int(n) for n in args.sizes.split(","))
    if len(sizes) < 2 or args.repeat < 1:
        sys.exit("need at least two mesh sizes and one run per case")
    if not args.no_build:
        subprocess.run(["cargo", "build", "--release", "--quiet"], check=True)
    binary = os.path.join("target", "release", "fem-forms")
    out = tempfile.mkdtemp(prefix="solve-exponent-")
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), "unknown CPU")
    print(f"# fem-forms solve membrane-radial, {os.cpu_count()} cores, {cpu}")
    print(f"# best of {args.repeat}; seconds = the report's `seconds`; "
          f"--linear-solver {args.linear_solver}")
    # the unmeasured run that makes the kernel give back its page cache first
    solve(binary, pairs[0], sizes[-1], args.linear_solver, out)
    print(f"{'pair':>9} {'N':>5} {'unknowns':>9} {'seconds':>8} {'peak MB':>8} "
          f"{'kB/primal':>10} {'solver':>9}")
    for pair in pairs:
        points = []
        for n in sizes:
            best_t, best_mb, used = math.inf, math.inf, "?"
            for _ in range(args.repeat):
                t, mb, used = solve(binary, pair, n, args.linear_solver, out)
                best_t = min(best_t, t)
                best_mb = min(best_mb, mb) if mb is not None else best_mb
            unknowns = (n - 1) ** 2
            points.append((unknowns, best_t))
            per = f"{best_mb * 1024 / unknowns:>10.2f}" if best_mb < math.inf else f"{'-':>10}"
            mb = f"{best_mb:>8.0f}" if best_mb < math.inf else f"{'-':>8}"
            print(f"{pair:>9} {n:>5} {unknowns:>9} {best_t:>8.3f} {mb} {per} {used:>9}")
        slope, _ = fit(points)
        local = fit(points[-2:])[0]
        print(f"{pair:>9} fitted exponent {slope:.3f} from {points[0][0]} to {points[-1][0]} "
              f"unknowns (last step {local:.3f})")


if __name__ == "__main__":
    main()
