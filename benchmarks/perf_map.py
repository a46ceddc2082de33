"""Name the compiled planners' functions in a ``perf`` profile.

Why: ``perf`` sees numba's machine code as anonymous addresses, so a profile of a plan says
"[JIT] 63 %" and nothing more. numba loads each function from its on-disk cache as an object
file; this script keeps those objects as they are loaded, reads their ELF symbol tables (name,
size) and asks numba's engine where each symbol landed, then writes ``/tmp/perf-PID.map``, the
file ``perf report`` reads to name JIT code. With it the thirteenth session found where a
5-joint default call spent its time (docs/peer-measurements.md): the certified edge check,
the distances and sin/cos took what they take in the tuned RRT; the Connect loop itself was
the difference.

Run numba's cache warm first (any plan of the same kind does it; functions compiled in this
process rather than loaded are not named), then::

    python benchmarks/perf_map.py fuzzy-rrt reports/eval/dof5/*.toml --seconds 8 &
    perf record -F 10000 -p "$(cat /tmp/perf_map.pid)" -- sleep 4
    perf report --no-children --sort symbol

The script plans the scenarios for the named planner (seeds 0..49, over and over) for
``--seconds`` after writing the map, so that ``perf record -p`` can attach to it.
"""

from __future__ import annotations

import argparse
import os
import struct
import sys
import time

_LOADED: list = []


def keep_loaded_objects() -> None:
    """Keep every object file numba loads from its cache, with the library it became (call
    before anything compiled is imported)."""
    import numba.core.codegen as codegen

    original = codegen.CPUCodeLibrary._unserialize.__func__

    def unserialize(cls, cg, state):
        library = original(cls, cg, state)
        if state[1] == "object":
            _LOADED.append((library, state[2][0]))
        return library

    codegen.CPUCodeLibrary._unserialize = classmethod(unserialize)


def elf_functions(obj: bytes) -> list[tuple[str, int]]:
    """``(name, size)`` of every sized function symbol of an ELF64 little-endian object."""
    shoff = struct.unpack_from("<Q", obj, 0x28)[0]
    entsize, count, _ = struct.unpack_from("<HHH", obj, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", obj, shoff + i * entsize) for i in range(count)]
    out = []
    for sec in sections:
        if sec[1] != 2:  # SHT_SYMTAB
            continue
        offset, size, link, sym_size = sec[4], sec[5], sec[6], sec[9]
        strings = sections[link][4]
        for k in range(size // sym_size):
            name, info, _, _, _, sz = struct.unpack_from("<IBBHQQ", obj, offset + k * sym_size)
            if info & 0xF == 2 and sz > 0:  # STT_FUNC
                end = obj.index(b"\0", strings + name)
                out.append((obj[strings + name:end].decode(), sz))
    return out


def write_perf_map(path: str | None = None) -> int:
    """Write ``/tmp/perf-PID.map`` for the functions loaded so far; return how many."""
    symbols = {}
    for library, obj in _LOADED:
        engine = library._codegen._engine
        for name, size in elf_functions(obj):
            try:
                address = engine.get_function_address(name)
            except Exception:  # a symbol the engine did not keep
                continue
            if address:
                symbols[address] = (name, size)
    path = path or f"/tmp/perf-{os.getpid()}.map"
    with open(path, "w", encoding="utf-8") as fh:
        for address in sorted(symbols):
            name, size = symbols[address]
            fh.write(f"{address:x} {size:x} {name}\n")
    return len(symbols)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("planner", help="a planner label, e.g. fuzzy-rrt or rrt:tuned")
    ap.add_argument("scenarios", nargs="+", help="scenario .toml files")
    ap.add_argument("--seconds", type=float, default=8.0, help="how long to plan after the map")
    args = ap.parse_args(argv)
    keep_loaded_objects()
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import plan_scenario

    scenarios = [load_scenario(p) for p in args.scenarios]
    for sc in scenarios:  # load (or compile) everything the loop will run
        plan_scenario(sc, args.planner, seed=0)
    n = write_perf_map()
    with open("/tmp/perf_map.pid", "w", encoding="utf-8") as fh:
        fh.write(str(os.getpid()))
    print(f"pid {os.getpid()}: {n} compiled functions named in /tmp/perf-{os.getpid()}.map",
          file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < args.seconds:
        for sc in scenarios:
            for seed in range(50):
                plan_scenario(sc, args.planner, seed=seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
