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
presents (here ``haswell``, no AVX-512), not the host's. Numba keys its cache on the CPU, so
each planner's kernels are first compiled natively for valgrind's CPU (:func:`valgrind_cpu`),
and the callgrind run loads them: a machine's first run, or the first after an edit to the
kernels, compiles at native speed (under valgrind, Fuzzy-RRT-Connect's kernels alone took 18
min after an edit), and later runs take 10-30 s per planner, two planners at a time. Needs
``valgrind`` and a C compiler with ``valgrind/callgrind.h``. Run on problems nobody tuned on::

    python benchmarks/cold_misses.py /tmp/eval-sample --problems 8 --seeds 3
    python benchmarks/cold_misses.py /tmp/eval-dual3 --planner fuzzy-rrt --planner rrt:tuned

To compare two versions of the code, run it from each checkout (``PYTHONPATH``) and compare
the per-call counts: they are the same (within 0.1 %) on every run of the same code.

``--by-function N`` says where the misses come from: the N compiled functions with the most
misses per call, each planner. Callgrind sees numba's compiled code as anonymous memory, so
the run also records every instruction's cost (``--dump-instr=yes``), keeps each loaded
library's object code (numba drops it once loaded; the child keeps a reference) and maps
addresses to functions with ``nm``'s symbol table of that object. A function's cost is its
own (callees counted where they are, inlined code counted in its caller); what runs outside
numba's code (Python, numpy, libc) is one row. Needs ``nm`` (binutils)::

    python benchmarks/cold_misses.py /tmp/eval-dual3 --problems 4 --by-function 12
"""

from __future__ import annotations

import argparse
import bisect
import json
import os
import re
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


def child(helper: str, planner: str, files: list[Path], seeds: int, max_iter: int,
          objects: Path | None = None) -> None:
    """Runs under callgrind: warm every call up uncounted, then count each call cold. With
    ``objects`` (a folder), also write there the object code of every compiled library the
    package loaded and ``objects.json`` (:func:`keep_objects`)."""
    import ctypes

    import numpy as np

    if objects is not None:
        from numba.core.codegen import CPUCodeLibrary

        loaded = CPUCodeLibrary._set_compiled_object

        def keep(library, code):  # numba drops a cached library's object once it is loaded
            library.kept_object_code = code
            return loaded(library, code)

        CPUCodeLibrary._set_compiled_object = keep

    from xfuzzy_rrt.planners.api import plan_scenario

    lib = ctypes.CDLL(helper)
    given, scenarios = warm_up(planner, files, max_iter)
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
    if objects is not None:
        keep_objects(objects)


def warm_up(planner: str, files: list[Path], max_iter: int):
    """Load the planner's settings and the problems, and plan each problem once (kernels
    loaded or compiled, set-ups remembered: not what a call costs); returns both."""
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import load_shipped_default, plan_scenario, preloaded

    # as evaluate passes them: plain fuzzy-rrt's shipped default and every peer's settings
    # loaded once (else each call resolves them again, which no timed call pays)
    given = load_shipped_default() if planner == "fuzzy-rrt" else preloaded(planner, None)
    scenarios = [load_scenario(f) for f in files]
    for sc in scenarios:
        plan_scenario(sc, planner, rulebook=given, seed=0, max_iter=max_iter)
    return given, scenarios


#: Prints the CPU numba compiles for (its name, then its features as numba flattens them).
CPU_PROBE = ("import llvmlite.binding as ll\n"
             "from numba.core.codegen import get_host_cpu_features\n"
             "print(ll.get_host_cpu_name())\nprint(get_host_cpu_features())")


def valgrind_cpu() -> dict[str, str]:
    """``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES`` as numba sees the CPU under valgrind
    (asked of a Python run under ``valgrind --tool=none``, ~10 s).

    Why: numba keys its cache on the CPU, and valgrind presents another one than the host
    (here ``haswell`` without AVX-512, on a Rocket Lake), so every kernel would compile under
    valgrind, several times slower than natively (18 min for Fuzzy-RRT-Connect's kernels after
    an edit). With these two set, a native run compiles exactly the code valgrind's run will
    load, under the same cache key."""
    done = subprocess.run(["valgrind", "--tool=none", "-q", sys.executable, "-c", CPU_PROBE],
                          capture_output=True, text=True)
    lines = done.stdout.split()
    if done.returncode != 0 or len(lines) != 2:
        raise SystemExit("cold_misses: cannot ask valgrind which CPU it presents: "
                         + (done.stderr.strip().splitlines() or ["no output"])[-1])
    return {"NUMBA_CPU_NAME": lines[0], "NUMBA_CPU_FEATURES": lines[1]}


def keep_objects(folder: Path) -> None:
    """Write each loaded overload of every ``xfuzzy_rrt`` dispatcher: its library's object
    code (``<n>.o``) and, in ``objects.json``, the file, the overload's entry symbol and the
    address it was loaded at (which places the object's symbols in memory)."""
    from numba.core.registry import CPUDispatcher

    folder.mkdir(parents=True, exist_ok=True)
    rows, seen = [], set()
    for name, module in sorted(sys.modules.items()):
        if not name.startswith("xfuzzy_rrt"):
            continue
        for value in list(vars(module).values()):
            if not isinstance(value, CPUDispatcher) or id(value) in seen:
                continue
            seen.add(id(value))
            for cres in value.overloads.values():
                code = getattr(cres.library, "kept_object_code", None)
                if code is None:  # compiled in this run, not loaded: numba keeps it itself
                    try:
                        code = cres.library._get_compiled_object()
                    except RuntimeError:
                        continue
                path = folder / f"{len(rows)}.o"
                path.write_bytes(code)
                symbol = cres.fndesc.llvm_func_name
                rows.append({"object": str(path), "symbol": symbol,
                             "address": cres.library.get_pointer_to_function(symbol)})
    (folder / "objects.json").write_text(json.dumps(rows))


def count(helper: Path, planner: str, files: list[Path], seeds: int, max_iter: int,
          work: Path, top: int = 0, cpu: dict[str, str] | None = None) -> dict:
    """One planner's per-call event counts (a callgrind run of :func:`child`); with ``top``,
    also its ``top`` costliest compiled functions under ``"functions"`` (:func:`by_function`).
    With ``cpu`` (:func:`valgrind_cpu`), the kernels are first compiled natively for that CPU
    (:func:`warm_up` in a process of its own), and the callgrind run loads them."""
    env = {**os.environ, **(cpu or {})}
    if cpu:
        done = subprocess.run([sys.executable, __file__, "--precompile", "--planner", planner,
                               "--max-iter", str(max_iter), *map(str, files)],
                              capture_output=True, text=True, env=env)
        if done.returncode != 0:
            raise SystemExit(f"cold_misses: compiling {planner} for valgrind's CPU failed:\n"
                             + _stderr_tail(done.stderr))
    tag = planner.replace(":", "_").replace("/", "_")
    out = work / f"{tag}.out"
    objects = work / f"{tag}.objects"
    cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--collect-atstart=no",
           "--cache-sim=yes", f"--LL={LL[0]},{LL[1]},{LL[2]}",
           *(["--dump-instr=yes"] if top else []),
           f"--callgrind-out-file={out}.%p", sys.executable, __file__, "--child", str(helper),
           "--planner", planner, "--seeds", str(seeds), "--max-iter", str(max_iter),
           *(["--objects", str(objects)] if top else []), *map(str, files)]
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    dumps = sorted(work.glob(f"{tag}.out.*.1"))
    if done.returncode != 0 or not dumps:
        raise SystemExit(f"cold_misses: the callgrind run of {planner} failed:\n"
                         + _stderr_tail(done.stderr))
    dump = dumps[-1].read_text()
    calls = len(files) * seeds
    row = {"planner": planner, **per_call(dump, calls)}
    if top:
        ranges = symbol_ranges(json.loads((objects / "objects.json").read_text()))
        if not ranges:
            raise SystemExit(f"cold_misses: no compiled function of {planner} could be placed "
                             "in memory (numba's object code was not kept)")
        row["functions"] = by_function(dump, ranges, calls)[:top]
    return row


def _header(lines: list[str], key: str, default: list[str] | None = None) -> list[str]:
    """The fields after ``key:`` on a callgrind dump's header line of that name."""
    found = next((line.split()[1:] for line in lines if line.startswith(key + ":")), default)
    if found is None:
        raise SystemExit(f"cold_misses: the dump has no {key}: line")
    return found


def _stderr_tail(text: str) -> str:
    """The last five lines of a failed child's stderr, for the one error that reports it."""
    return "\n".join(text.strip().splitlines()[-5:])


def per_call(dump: str, calls: int) -> dict[str, float]:
    """The events of a callgrind dump (its ``events:`` and ``summary:`` lines) divided by the
    ``calls`` it collected, with ``LL`` the sum of the last-level misses."""
    lines = dump.splitlines()
    values = dict(zip(_header(lines, "events"), map(int, _header(lines, "summary"))))
    missing = [e for e in EVENTS if e not in values]
    if missing:
        raise SystemExit(f"cold_misses: the dump has no {', '.join(missing)} (cache simulation "
                         "off?)")
    return {"calls": calls, **{e: values[e] / calls for e in EVENTS},
            "LL": (values["ILmr"] + values["DLmr"] + values["DLmw"]) / calls}


def instruction_costs(dump: str) -> tuple[list[str], dict[int, list[int]]]:
    """The event names and each instruction address's *own* cost in a callgrind dump made
    with ``--dump-instr=yes`` (``positions: instr line``). A cost line's positions are
    absolute (``0x...``), relative (``+n``, ``-n``) or repeated (``*``); the line after a
    ``calls=`` line is the callee's inclusive cost at the call site, which is skipped (the
    callee's own lines count it)."""
    lines = dump.splitlines()
    events = _header(lines, "events")
    positions = _header(lines, "positions", ["line"])
    if positions[0] != "instr":
        raise SystemExit("cold_misses: the dump has no instruction addresses (--dump-instr=yes)")
    width = len(positions)
    last = [0] * width
    costs: dict[int, list[int]] = {}
    skip = False
    for line in lines:
        if line.startswith("calls="):
            skip = True
            continue
        if not line or not (line[0] in "+-*" or line[0].isdigit()):
            continue
        fields = line.split()
        for k in range(width):
            tok = fields[k]
            last[k] = (last[k] if tok == "*" else last[k] + int(tok) if tok[0] in "+-"
                       else int(tok, 16) if tok.startswith("0x") else int(tok))
        if skip:
            skip = False
            continue
        values = [int(v) for v in fields[width:]]
        row = costs.setdefault(last[0], [0] * len(events))
        for k, v in enumerate(values):
            row[k] += v
    return events, costs


def demangle(symbol: str) -> str:
    """A numba symbol as ``module.function[tag]`` (``cpython.`` marks the wrapper Python
    calls; ``[vN]`` tells specialisations of one function apart), else the symbol as it is.
    Numba's Itanium-style names (``_ZN10xfuzzy_rrt8planners...B3v25...E...``) are too long
    for ``c++filt`` to take every time, and only the qualified name and its tag matter here."""
    start = symbol.find("_ZN")
    if start < 0:
        return symbol
    i, parts = start + 3, []
    while i < len(symbol) and symbol[i].isdigit():
        j = i
        while j < len(symbol) and symbol[j].isdigit():
            j += 1
        n = int(symbol[i:j])
        if j == len(symbol) or j + n > len(symbol):  # cut short: keep the parts read
            break
        parts.append(symbol[j:j + n])
        i = j + n
    if not parts:
        return symbol
    tag = ""
    m = re.match(r"B(\d+)", symbol[i:])
    if m:
        n = int(m.group(1))
        tag = f"[{symbol[i + len(m.group(0)):i + len(m.group(0)) + n]}]"
    return ".".join(parts).replace("_3clocals_3e", "<locals>") + tag


def symbol_ranges(placed: list[dict]) -> list[tuple[int, int, str]]:
    """``(start, end, name)`` in memory of every function of the objects :func:`keep_objects`
    wrote, sorted: each object is placed by its entry symbol's loaded address minus that
    symbol's offset in the object (numba loads an object's code as one block)."""
    ranges = []
    for row in placed:
        listing = subprocess.run(["nm", "-S", row["object"]], capture_output=True,
                                 text=True).stdout
        symbols = []
        for line in listing.splitlines():
            fields = line.split()
            if len(fields) == 4 and fields[2] in "TtWw":
                symbols.append((int(fields[0], 16), int(fields[1], 16), fields[3]))
        entry = [offset for offset, _, name in symbols if name == row["symbol"]]
        if not entry:
            continue
        base = row["address"] - entry[0]
        ranges += [(base + offset, base + offset + size, demangle(name))
                   for offset, size, name in symbols if size > 0]
    return sorted(ranges)


#: The row that gathers what ran outside numba's compiled code.
OUTSIDE = "(outside compiled code: Python, numpy, libc)"


def by_function(dump: str, ranges: list[tuple[int, int, str]], calls: int) -> list[dict]:
    """Per compiled function (by :func:`demangle`'d name; copies linked into several
    libraries add up) its own ``Ir``, ``ILmr``, ``DLmr``, ``DLmw`` and ``LL`` per call, the
    costliest (``LL``) first, with :data:`OUTSIDE` for addresses no range holds."""
    events, costs = instruction_costs(dump)
    starts = [r[0] for r in ranges]
    totals: dict[str, list[int]] = {}
    for address, values in costs.items():
        k = bisect.bisect_right(starts, address) - 1
        name = ranges[k][2] if k >= 0 and address < ranges[k][1] else OUTSIDE
        row = totals.setdefault(name, [0] * len(events))
        for j, v in enumerate(values):
            row[j] += v
    index = {e: k for k, e in enumerate(events)}
    rows = []
    for name, values in totals.items():
        per = {e: values[index[e]] / calls for e in ("Ir", "ILmr", "DLmr", "DLmw")}
        rows.append({"function": name, **per, "LL": per["ILmr"] + per["DLmr"] + per["DLmw"]})
    return sorted(rows, key=lambda r: (-r["LL"], r["function"]))


def measure(files: list[Path], planners: list[str], seeds: int = 3,
            max_iter: int = 10_000, top: int = 0) -> list[dict]:
    """Per planner (in parallel, two at a time) the per-call counts over ``files`` x
    ``seeds`` cold calls: ``Ir``, ``ILmr``, ``DLmr``, ``DLmw`` (callgrind's names), ``LL``
    (their sum of misses) and ``calls``; with ``top``, ``functions`` too (:func:`count`)."""
    if shutil.which("valgrind") is None:
        raise SystemExit("cold_misses: valgrind is not installed")
    if top and shutil.which("nm") is None:
        raise SystemExit("cold_misses: --by-function needs nm (binutils)")
    cpu = valgrind_cpu()
    with tempfile.TemporaryDirectory(prefix="cold-misses-") as tmp:
        work = Path(tmp)
        helper = build_helper(work)
        with ThreadPoolExecutor(max_workers=2) as pool:
            return list(pool.map(
                lambda pl: count(helper, pl, files, seeds, max_iter, work, top, cpu), planners))


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


class _OneLineParser(argparse.ArgumentParser):
    """An argument error is one line naming the option (exit 2), not argparse's usage block."""

    def error(self, message):
        print(f"cold_misses: {message}", file=sys.stderr)
        raise SystemExit(2)


def main(argv=None) -> int:
    p = _OneLineParser(description=__doc__.split("\n")[0])
    p.add_argument("paths", nargs="+", help="scenario files or folders (a folder: its first "
                   "--problems files)")
    p.add_argument("--planner", action="append",
                   help="planner label (repeatable; default: fuzzy-rrt and rrt:tuned)")
    p.add_argument("--problems", type=_at_least_one, default=8,
                   help="problems per folder (first N)")
    p.add_argument("--seeds", type=_at_least_one, default=3, help="seeds per problem")
    p.add_argument("--max-iter", type=_at_least_one, default=10_000)
    p.add_argument("--by-function", type=_at_least_one, metavar="N",
                   help="also print each planner's N compiled functions with the most misses")
    p.add_argument("--child", help=argparse.SUPPRESS)
    p.add_argument("--objects", help=argparse.SUPPRESS)
    p.add_argument("--precompile", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    planners = args.planner or ["fuzzy-rrt", "rrt:tuned"]
    if args.precompile:
        warm_up(planners[0], [Path(f) for f in args.paths], args.max_iter)
        return 0
    if args.child:
        child(args.child, planners[0], [Path(f) for f in args.paths], args.seeds, args.max_iter,
              Path(args.objects) if args.objects else None)
        return 0
    from xfuzzy_rrt.errors import InputError

    try:
        files = checked_files(args.paths, args.problems, planners)
    except InputError as err:
        print(f"cold_misses: {err}", file=sys.stderr)
        return 2
    rows = measure(files, planners, args.seeds, args.max_iter, args.by_function or 0)
    print(f"{rows[0]['calls']} cold calls per planner; per call (simulated {LL[0] >> 20} MB "
          "last level, evicted before each call):")
    print(f"{'planner':24s} {'Ir':>9s} {'ILmr':>7s} {'DLmr':>7s} {'DLmw':>7s} {'LL misses':>10s}"
          f" {'/ first':>8s}")
    for r in rows:
        print(f"{r['planner']:24s} {r['Ir']:9.0f} {r['ILmr']:7.0f} {r['DLmr']:7.0f}"
              f" {r['DLmw']:7.0f} {r['LL']:10.0f} {r['LL'] / rows[0]['LL']:8.3f}")
    for r in rows:
        if "functions" not in r:
            continue
        print(f"\n{r['planner']}: its {len(r['functions'])} costliest functions, per call")
        print(f"{'Ir':>9s} {'ILmr':>7s} {'DLmr':>7s} {'DLmw':>7s} {'LL':>7s}  function")
        for f in r["functions"]:
            print(f"{f['Ir']:9.0f} {f['ILmr']:7.0f} {f['DLmr']:7.0f} {f['DLmw']:7.0f}"
                  f" {f['LL']:7.0f}  {f['function']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
