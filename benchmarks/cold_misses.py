"""Cold calls counted, not timed: simulated cache misses per planner call under callgrind.

Why: a call made between other work starts with its code and data out of the caches, and there
its cost is mostly last-level misses (``rrt:tuned``'s compiled 2-joint entry with no iteration,
cold: ~2,100 misses and ~100 us, ~50 ns each). Timing that is noisy on a shared machine: the
same script and code gave 95-113 us one hour and 146-490 us the next
(docs/peer-measurements.md, twenty-fifth session), so a change worth 1-3 us could not be
decided. Callgrind's cache simulator counts the same misses on every run (within 0.1 %),
whatever the machine's state: this script calls each planner on the given problems as
``benchmarks/cold_calls.py`` does, with the simulated caches evicted before every call, and
prints per call the instructions (Ir), the simulated last-level misses for code (ILmr) and data
(DLmr read, DLmw write) and their sum, and each planner's misses over the first one's.

How: each planner runs in its own process under ``valgrind --tool=callgrind`` with
instrumentation off while Python starts and the kernels load, then on (a few lines of C,
compiled here with ``cc``, issues callgrind's client requests through ``ctypes``); before each
call a 16 MB array is written (twice the simulated 8 MB last level), and only the call itself
is collected. The whole ``plan_scenario`` call is counted (set-up memo, kernel, result), with
each planner's rulebooks or settings loaded once, as ``evaluate`` calls it. What it does not
model: the TLB, the branch predictor and prefetching (sequential code misses cost less than
scattered data ones). The code counted is what numba compiles for the CPU that valgrind
presents (no AVX-512), not the host's: numba keys its cache on the CPU, so the first run on a
machine compiles every kernel under valgrind (several minutes: over 5 in a CI run, which was
stopped) and later runs take 10-30 s per planner, two planners at a time. Needs ``valgrind``
and a C compiler with ``valgrind/callgrind.h``. Run on problems nobody tuned on::

    python benchmarks/cold_misses.py /tmp/eval-sample --problems 8 --seeds 3
    python benchmarks/cold_misses.py /tmp/eval-dual3 --planner fuzzy-rrt --planner rrt:tuned

To compare two versions of the code, run it from each checkout (``PYTHONPATH``) and compare
the per-call counts: they are the same (within 0.1 %) on every run of the same code.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

#: The simulated last level (bytes, ways, line): a fixed size, so counts do not depend on what
#: the host's L3 is (valgrind would otherwise take it, 480 MB on this machine).
LL = (8 * 2**20, 16, 64)
EVICT_BYTES = 2 * LL[0]
EVENTS = ("Ir", "Dr", "Dw", "I1mr", "D1mr", "D1mw", "ILmr", "DLmr", "DLmw")

HELPER_C = """#include <valgrind/callgrind.h>
void cg_start(void) { CALLGRIND_START_INSTRUMENTATION; }
void cg_toggle(void) { CALLGRIND_TOGGLE_COLLECT; }
void cg_dump(void) { CALLGRIND_DUMP_STATS_AT("calls"); }
"""


def build_helper(folder: Path) -> Path:
    """Compile the client-request helper into ``folder``; one clear error if that fails."""
    src = folder / "cg_helper.c"
    lib = folder / "libcg_helper.so"
    src.write_text(HELPER_C)
    cc = os.environ.get("CC", "cc")
    done = subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(lib), str(src)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"cold_misses: cannot build the callgrind helper with {cc} "
                         f"(needs valgrind/callgrind.h): {done.stderr.strip()}")
    return lib


def child(helper: str, planner: str, files: list[Path], seeds: int, max_iter: int) -> None:
    """Runs under callgrind: warm every call up uncounted, then count each call cold."""
    import ctypes

    import numpy as np

    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import load_shipped_default, plan_scenario, preloaded

    lib = ctypes.CDLL(helper)
    # as evaluate passes them: plain fuzzy-rrt's shipped default and every peer's settings
    # loaded once (else each call resolves them again, which no timed call pays)
    given = load_shipped_default() if planner == "fuzzy-rrt" else preloaded(planner, None)
    scenarios = [load_scenario(f) for f in files]
    for sc in scenarios:  # kernels loaded, set-ups remembered: not what a call costs
        plan_scenario(sc, planner, rulebook=given, seed=0, max_iter=max_iter)
    junk = np.zeros(EVICT_BYTES // 8)
    lib.cg_start()
    junk += 1.0
    for sc in scenarios:
        for seed in range(seeds):
            junk += 1.0
            lib.cg_toggle()
            plan_scenario(sc, planner, rulebook=given, seed=seed, max_iter=max_iter)
            lib.cg_toggle()
    lib.cg_dump()


def count(helper: Path, planner: str, files: list[Path], seeds: int, max_iter: int,
          work: Path) -> dict[str, float]:
    """One planner's per-call event counts (a callgrind run of :func:`child`)."""
    tag = planner.replace(":", "_").replace("/", "_")
    out = work / f"{tag}.out"
    cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--collect-atstart=no",
           "--cache-sim=yes", f"--LL={LL[0]},{LL[1]},{LL[2]}",
           f"--callgrind-out-file={out}.%p", sys.executable, __file__, "--child", str(helper),
           "--planner", planner, "--seeds", str(seeds), "--max-iter", str(max_iter),
           *map(str, files)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    dumps = sorted(work.glob(f"{tag}.out.*.1"))
    if done.returncode != 0 or not dumps:
        tail = "\n".join(done.stderr.strip().splitlines()[-5:])
        raise SystemExit(f"cold_misses: the callgrind run of {planner} failed:\n{tail}")
    return {"planner": planner, **per_call(dumps[-1].read_text(), len(files) * seeds)}


def per_call(dump: str, calls: int) -> dict[str, float]:
    """The events of a callgrind dump (its ``events:`` and ``summary:`` lines) divided by the
    ``calls`` it collected, with ``LL`` the sum of the last-level misses."""
    lines = dump.splitlines()
    names = next(line for line in lines if line.startswith("events:")).split()[1:]
    values = dict(zip(names, map(int, next(line for line in lines
                                           if line.startswith("summary:")).split()[1:])))
    missing = [e for e in EVENTS if e not in values]
    if missing:
        raise SystemExit(f"cold_misses: the dump has no {', '.join(missing)} (cache simulation "
                         "off?)")
    return {"calls": calls, **{e: values[e] / calls for e in EVENTS},
            "LL": (values["ILmr"] + values["DLmr"] + values["DLmw"]) / calls}


def measure(files: list[Path], planners: list[str], seeds: int = 3,
            max_iter: int = 10_000) -> list[dict[str, float]]:
    """Per planner (in parallel, two at a time) the per-call counts over ``files`` x
    ``seeds`` cold calls: ``Ir``, ``ILmr``, ``DLmr``, ``DLmw`` (callgrind's names), ``LL``
    (their sum of misses) and ``calls``."""
    if shutil.which("valgrind") is None:
        raise SystemExit("cold_misses: valgrind is not installed")
    with tempfile.TemporaryDirectory(prefix="cold-misses-") as tmp:
        work = Path(tmp)
        helper = build_helper(work)
        with ThreadPoolExecutor(max_workers=2) as pool:
            return list(pool.map(lambda pl: count(helper, pl, files, seeds, max_iter, work),
                                 planners))


def _at_least_one(text: str) -> int:
    """An argparse type: a whole number of 1 or more."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def checked_files(paths: list[str], problems: int, planners: list[str]) -> list[Path]:
    """The first ``problems`` scenario files of each path, every one loaded and every planner
    label parsed here, so that a typo is one line before any callgrind run starts (each costs
    10-30 s of start-up) rather than a failed run's stderr after it."""
    from xfuzzy_rrt.bench.runner import scenario_files
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import check_planner

    for planner in planners:
        check_planner(planner, "--planner")
    files = [f for path in paths for f in scenario_files([Path(path)])[:problems]]
    for f in files:
        load_scenario(f)
    return files


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("paths", nargs="+", help="scenario files or folders (a folder: its first "
                   "--problems files)")
    p.add_argument("--planner", action="append",
                   help="planner label (repeatable; default: fuzzy-rrt and rrt:tuned)")
    p.add_argument("--problems", type=_at_least_one, default=8,
                   help="problems per folder (first N)")
    p.add_argument("--seeds", type=_at_least_one, default=3, help="seeds per problem")
    p.add_argument("--max-iter", type=_at_least_one, default=10_000)
    p.add_argument("--child", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    planners = args.planner or ["fuzzy-rrt", "rrt:tuned"]
    if args.child:
        child(args.child, planners[0], [Path(f) for f in args.paths], args.seeds, args.max_iter)
        return 0
    from xfuzzy_rrt.errors import InputError

    try:
        files = checked_files(args.paths, args.problems, planners)
    except InputError as err:
        print(f"cold_misses: {err}", file=sys.stderr)
        return 2
    rows = measure(files, planners, args.seeds, args.max_iter)
    print(f"{rows[0]['calls']} cold calls per planner; per call (simulated {LL[0] >> 20} MB "
          "last level, evicted before each call):")
    print(f"{'planner':24s} {'Ir':>9s} {'ILmr':>7s} {'DLmr':>7s} {'DLmw':>7s} {'LL misses':>10s}"
          f" {'/ first':>8s}")
    for r in rows:
        print(f"{r['planner']:24s} {r['Ir']:9.0f} {r['ILmr']:7.0f} {r['DLmr']:7.0f}"
              f" {r['DLmw']:7.0f} {r['LL']:10.0f} {r['LL'] / rows[0]['LL']:8.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
