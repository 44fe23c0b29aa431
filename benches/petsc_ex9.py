#!/usr/bin/env python3
"""fem-forms against PETSc's SNESVI on the same obstacle problem (issue 15).

PETSc's SNES tutorial ex9 (Ed Bueler's radial obstacle problem on (-2,2)^2, the
5-point scheme) with reduced-space Newton, grid sequencing and geometric multigrid:

    ex9 -snes_type vinewtonrsls -snes_grid_sequence K -pc_type mg -log_view

against `fem-forms solve membrane-radial --pair P --mesh-size N --json` on the same grid
(N = 4 * 2^K cells per side, (N+1)^2 nodes). p1-nodal on the right-diagonal triangles
is ex9's scheme, so both print the same errors |u-uexact|_inf and av |u-uexact| to
every digit (the script checks this): the comparison is of solvers, not of methods.

Measures, best of --repeat runs each: the solve (PETSc: the SNESSolve event of
-log_view; fem-forms: its `seconds`, assembly and all nested levels), the whole process
(wall clock) and its peak memory (GNU time's maximum resident set size), and prints the
ratios fem-forms / PETSc (below 1: fem-forms faster).

Needs PETSc's development files: Debian's `petsc-dev` (3.18 on bookworm). When they are
missing and apt-get is available as root, the script installs them (--install); the Rust
benchmarks never depend on PETSc. Usage, from the repository root:

    python3 benches/petsc_ex9.py [--grids 257,513,1025] [--repeat 3] [--install]
"""

import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

PKG_CONFIG_PATH = "/usr/lib/petsc/lib/pkgconfig"
EX9_GLOB = "/usr/share/petsc/*/share/petsc/examples/src/snes/tutorials/ex9.c"
PAIRS = ["p1-nodal", "p1-p0"]


def run(cmd, env=None, check=True):
    result = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if check and result.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{result.stdout}\n{result.stderr}")
    return result


def petsc_flags():
    env = dict(os.environ, PKG_CONFIG_PATH=PKG_CONFIG_PATH)
    result = run(["pkg-config", "--cflags", "--libs", "PETSc"], env=env, check=False)
    return result.stdout.split() if result.returncode == 0 else None


def ensure_petsc(install):
    flags = petsc_flags()
    sources = glob.glob(EX9_GLOB)
    if flags and sources:
        return flags, sources[0]
    if not install:
        sys.exit("PETSc's development files (Debian petsc-dev) are not installed: "
                 "rerun with --install (apt-get, as root) or install petsc-dev yourself")
    if shutil.which("apt-get") is None or os.geteuid() != 0:
        sys.exit("--install needs apt-get and root")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    run(["apt-get", "update", "-qq"], env=env)
    run(["apt-get", "install", "-y", "-qq", "petsc-dev"], env=env)
    flags, sources = petsc_flags(), glob.glob(EX9_GLOB)
    if not (flags and sources):
        sys.exit("petsc-dev installed, but pkg-config or ex9.c is still missing")
    return flags, sources[0]


def build_ex9(flags, source, directory):
    binary = os.path.join(directory, "ex9")
    run(["mpicc", "-O2", source, "-o", binary] + flags + ["-lm"])
    return binary


def timed(cmd, env=None):
    """(stdout, wall seconds, peak resident MB) of one run under GNU time."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        result = run(["/usr/bin/time", "-f", "%e %M", "-o", t.name] + cmd, env=env)
        wall, kb = t.read().split()[-2:]
    return result.stdout, float(wall), float(kb) / 1024.0


def petsc_run(ex9, k, repeat):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_btl_vader_single_copy_mechanism="none")
    best = None
    for _ in range(repeat):
        out, wall, mb = timed([ex9, "-snes_type", "vinewtonrsls", "-snes_grid_sequence",
                               str(k), "-pc_type", "mg", "-log_view"], env=env)
        solve = float(re.search(r"^SNESSolve\s+\d+\s+\S+\s+(\S+)", out, re.M).group(1))
        errors = re.search(r"av \|u-uexact\|\s*=\s*(\S+),\s*\|u-uexact\|_inf\s*=\s*(\S+)", out)
        row = dict(solve=solve, wall=wall, mb=mb,
                   mean=float(errors.group(1)), max=float(errors.group(2)))
        best = row if best is None else {key: min(best[key], row[key]) for key in row}
    return best


def fem_forms_run(binary, n, pair, repeat, out):
    best = None
    for _ in range(repeat):
        stdout, wall, mb = timed([binary, "solve", "membrane-radial", "--pair", pair,
                                  "--mesh-size", str(n), "--json", "--out", out])
        report = json.loads(stdout)
        row = dict(solve=report["seconds"], wall=wall, mb=mb,
                   mean=report["error_vertex_mean"], max=report["error_vertex_max"])
        best = row if best is None else {key: min(best[key], row[key]) for key in row}
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grids", default="257,513,1025",
                        help="grid sizes (nodes per side, 4*2^K+1), comma-separated")
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (best kept)")
    parser.add_argument("--install", action="store_true",
                        help="install petsc-dev with apt-get when missing")
    args = parser.parse_args()
    grids = [int(g) for g in args.grids.split(",")]
    for g in grids:
        if g < 9 or (g - 1) % 4 or ((g - 1) // 4) & ((g - 1) // 4 - 1):
            sys.exit(f"grid {g} is not 4*2^K+1 with K >= 1 (ex9 refines a 5x5 grid)")
    flags, source = ensure_petsc(args.install)
    work = tempfile.mkdtemp(prefix="petsc-ex9-")
    ex9 = build_ex9(flags, source, work)
    run(["cargo", "build", "--release", "--quiet"])
    binary = os.path.join("target", "release", "fem-forms")
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                if l.startswith("model name")), "unknown CPU")
    version = re.search(r"/petsc/([0-9.]+)/", source)
    print(f"# PETSc {version.group(1) if version else '?'} ex9 vs fem-forms, {os.cpu_count()} cores, {cpu}")
    print(f"# best of {args.repeat}; solve = SNESSolve / fem-forms `seconds`; "
          "process = wall clock; ratios fem-forms / PETSc")
    print(f"{'grid':>6} {'tool':>16} {'|e|_inf':>10} {'av |e|':>10} {'solve s':>8} "
          f"{'process s':>9} {'peak MB':>8} {'solve ×':>8} {'process ×':>9} {'memory ×':>8}")
    for g in grids:
        k = ((g - 1) // 4).bit_length() - 1
        petsc = petsc_run(ex9, k, args.repeat)
        print(f"{g:>5}² {'PETSc ex9':>16} {petsc['max']:>10.3e} {petsc['mean']:>10.3e} "
              f"{petsc['solve']:>8.3f} {petsc['wall']:>9.2f} {petsc['mb']:>8.0f}")
        for pair in PAIRS:
            ours = fem_forms_run(binary, g - 1, pair, args.repeat, work)
            if pair == "p1-nodal" and (f"{ours['max']:.3e}" != f"{petsc['max']:.3e}"
                                       or f"{ours['mean']:.3e}" != f"{petsc['mean']:.3e}"):
                print(f"  warning: p1-nodal errors differ from ex9's: not the same discrete problem")
            print(f"{g:>5}² {'fem-forms ' + pair:>16} {ours['max']:>10.3e} {ours['mean']:>10.3e} "
                  f"{ours['solve']:>8.3f} {ours['wall']:>9.2f} {ours['mb']:>8.0f} "
                  f"{ours['solve'] / petsc['solve']:>8.2f} {ours['wall'] / petsc['wall']:>9.2f} "
                  f"{ours['mb'] / petsc['mb']:>8.2f}")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
