"""Generated garbage never breaks an input parser: one clean error, exit 2, nothing written.

Valid inputs (scenario TOML, rulebook ``.fis``/``rulebook.toml`` text, FLL files for
``rules import``) are mutated at three levels — bytes (flips, insertions, deletions,
truncation, junk), tokens (words and punctuation deleted, duplicated, swapped or replaced by
format keywords) and values (numbers replaced by NaN, inf, 1e308, -0.0, 5e-324, huge integers,
strings, empty arrays) — and fed through the CLI entry point the console script uses
(:func:`xfuzzy_rrt.cli.main.main`, in-process for speed; a few cases through the real
``xfuzzy-rrt`` too). Whatever the input, the outcome must be one of:

- accepted: exit 0 (or 1 for "no path found"), a complete output file, and for a plan that
  succeeded, a path that the independent shapely oracle finds collision-free;
- rejected: exit 2, every stderr line ``error: FILE[:LINE]: ...`` naming the input (exactly one
  line for a scenario), no traceback, no output file and no stray temporary file;

and each case must finish within ``CASE_LIMIT_S`` (a SIGALRM turns a hang into a failure).

Budgets: the normal suite runs a fixed, fast number of cases per input kind; the ``fuzz``
marker selects the same properties with a large budget (``pytest -m fuzz``).
"""

from __future__ import annotations

import contextlib
import io
import math
import random
import re
import shutil
import signal
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import FIXTURES, PROJECT, shared_scenarios
from exact_geometry import Oracle
from xfuzzy_rrt.cli.main import main

#: Wall-clock limit for one case (generous: the machine is shared; a hang is minutes).
CASE_LIMIT_S = 30
#: Cases per input kind: (normal suite, ``-m fuzz``).
BUDGET = {"scenario": (100, 2000), "rulebook": (50, 1000), "fll": (40, 1000)}

EXPERT = PROJECT / "rulebooks" / "expert"
SCENARIO_SEEDS = sorted((FIXTURES / "scenarios").glob("*.toml")) + [
    p for p in shared_scenarios() if p.stem in ("paper-reference", "narrow-gap", "sample-03")]
SCENARIO_TEXTS = {p.name: p.read_bytes() for p in SCENARIO_SEEDS}
RULEBOOK_FILES = sorted(p.name for p in EXPERT.iterdir() if p.is_file())
RULEBOOK_TEXTS = {name: (EXPERT / name).read_bytes() for name in RULEBOOK_FILES}


def _export_fll() -> dict[str, bytes]:
    from xfuzzy_rrt.fuzzy.fll import export_fll
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    with tempfile.TemporaryDirectory() as tmp:
        paths = export_fll(load_rulebook(EXPERT), tmp)
        return {p.name: p.read_bytes() for p in paths}


FLL_TEXTS = _export_fll()

# ------------------------------------------------------------------------------ mutations

#: Replacement values: the edges of float64 and of the TOML/FIS/FLL number syntax.
EDGE_VALUES = [
    "nan", "-nan", "+nan", "inf", "-inf", "+inf", "1e308", "-1e308", "1e309", "-0.0", "0.0",
    "0", "-0", "5e-324", "1e-9", "-1e-9", "2.2250738585072014e-308", "1.7976931348623157e308",
    "9" * 400, "-" + "9" * 40, "1_000", "0x10", "0b1", "1e", ".5", "5.", "1.0.0", "--1",
    "\"1.0\"", "\"\"", "[]", "[[]]", "{}", "true", "NaN", "Infinity", "1,5", "10000000000",
]

#: Words of the three formats (and a few strangers) for token-level mutations.
TOKENS = [
    # TOML / scenario
    "name", "arm", "links", "base", "link_radius", "joint_limits_deg", "start", "goal",
    "q_deg", "obstacles", "type", "circle", "box", "center", "radius", "min", "max",
    "[arm]", "[start]", "[goal]", "[[obstacles]]", "[provenance]", "=", "[", "]", "{", "}",
    ",", "\"", "'", "\"\"\"", "#", "\n", "\r\n", "\t", " ", ".", "format", "format_version",
    "bounds_mode", "relative", "absolute", "kind", "description",
    # FIS
    "output", "input", "range", "terms", "peaks", "if", "is", "and", "then", "end", "r0:",
    "r624:", "r625:", "r-1:", "goal_bias", "step_size", "bound_1", "angle_to_goal",
    "dist_to_goal", "angle_to_obstacle", "dist_to_obstacle", "near", "far", "any", "xfuzzy-rrt-fis",
    # FLL
    "Engine:", "InputVariable:", "OutputVariable:", "RuleBlock:", "term:", "rule:", "range:",
    "Triangle", "Ramp", "Constant", "description:", "xfuzzy-rrt", "with", "enabled:", "lock-range:",
    "aggregation:", "defuzzifier:", "conjunction:", "activation:", "Maximum", "none",
    "{\"name\": \" \"}", "[1, 2]", "null",
    # strangers
    "\x00", "\ufeff", "é", "\u202e", "😀", "\\", "\\u0000",
] + EDGE_VALUES

_TOKEN = re.compile(r"\s+|[A-Za-z_][A-Za-z0-9_\-]*:?|[-+]?[0-9][0-9_.eE+\-]*|.", re.S)
_NUMBER = re.compile(r"(?<![\w.\-+])[-+]?(?:\d[\d_]*\.?\d*(?:[eE][-+]?\d+)?|inf|nan)(?![\w.])")


@st.composite
def byte_level(draw, data: bytes) -> bytes:
    b = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["flip", "set", "insert", "delete", "truncate", "duplicate"]))
        pos = draw(st.integers(0, max(len(b) - 1, 0)))
        if op == "flip" and b:
            b[pos] ^= 1 << draw(st.integers(0, 7))
        elif op == "set" and b:
            b[pos] = draw(st.sampled_from([0, 0x0A, 0x0D, 0x22, 0x23, 0x3D, 0x5B, 0x5D, 0x80,
                                           0xC3, 0xEF, 0xFF, draw(st.integers(0, 255))]))
        elif op == "insert":
            b[pos:pos] = draw(st.binary(min_size=1, max_size=8))
        elif op == "delete":
            del b[pos:pos + draw(st.integers(1, 64))]
        elif op == "truncate":
            del b[pos:]
        elif op == "duplicate":
            n = draw(st.integers(1, 200))
            b[pos:pos] = b[pos:pos + n]
    return bytes(b)


@st.composite
def token_level(draw, data: bytes) -> bytes:
    toks = _TOKEN.findall(data.decode("utf-8"))
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(toks) - 1))
        op = draw(st.sampled_from(["delete", "duplicate", "swap", "replace", "insert"]))
        if op == "delete":
            del toks[i]
        elif op == "duplicate":
            toks.insert(i, toks[i])
        elif op == "swap":
            j = draw(st.integers(0, len(toks) - 1))
            toks[i], toks[j] = toks[j], toks[i]
        elif op == "replace":
            toks[i] = draw(st.sampled_from(TOKENS))
        else:
            toks.insert(i, draw(st.sampled_from(TOKENS)))
        if not toks:
            break
    return "".join(toks).encode("utf-8")


@st.composite
def value_level(draw, data: bytes) -> bytes:
    text = data.decode("utf-8")
    spans = [m.span() for m in _NUMBER.finditer(text)]
    if not spans:
        return data
    chosen = sorted(set(draw(st.lists(st.integers(0, len(spans) - 1), min_size=1, max_size=3))))
    out, last = [], 0
    for k in chosen:
        a, b = spans[k]
        out += [text[last:a], draw(st.sampled_from(EDGE_VALUES) | st.floats().map(repr))]
        last = b
    out.append(text[last:])
    return "".join(out).encode("utf-8")


def mutated(data: bytes):
    return st.one_of(byte_level(data), token_level(data), value_level(data))


# ------------------------------------------------------------------------- running a case


class _CaseTimeout(Exception):
    pass


def _alarm(signum, frame):  # pragma: no cover - only on a hang
    raise _CaseTimeout(f"case exceeded {CASE_LIMIT_S} s")


def run_main(args: list[str], limit: bool = True) -> tuple[int, str, str]:
    """``main(args)`` in-process with stdout/stderr captured and, with ``limit``, a
    wall-clock limit that turns a hang into a failure (``limit=False``: a case whose time is
    a matter of load, measured in ``benchmarks/`` instead)."""
    out, err = io.StringIO(), io.StringIO()
    if limit:
        old = signal.signal(signal.SIGALRM, _alarm)
        signal.alarm(CASE_LIMIT_S)
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main([str(a) for a in args])
    finally:
        if limit:
            signal.alarm(0)
            signal.signal(signal.SIGALRM, old)
    if limit:
        assert time.perf_counter() - t0 < CASE_LIMIT_S
    return code, out.getvalue(), err.getvalue()


def assert_rejected_cleanly(code: int, err: str, where: Path, one_line: bool) -> None:
    """Exit 2, and every stderr line is ``error: <where>[...]: <message>``."""
    assert code == 2, err
    assert "Traceback" not in err
    lines = err.splitlines()
    assert lines, "exit 2 without an error line"
    if one_line:
        assert len(lines) == 1, err
    pattern = re.compile(r"error: " + re.escape(str(where)) + r"[^:\n]*(?::\d+)?: \S.*\Z")
    for line in lines:
        assert pattern.match(line), f"not 'error: FILE[:LINE]: ...': {line!r}"


def only_inputs_left(tmp: Path, inputs: set[str]) -> None:
    """No output and no temporary file next to the inputs."""
    assert sorted(p.name for p in tmp.iterdir()) == sorted(inputs)


def _fuzz_settings(kind: str, big: bool):
    return settings(max_examples=BUDGET[kind][1 if big else 0], deadline=None, database=None,
                    suppress_health_check=list(HealthCheck))


def _two_budgets(kind: str, strategy, body):
    """The property as two tests: a fast fixed budget, and a large one under ``-m fuzz``."""
    fast = _fuzz_settings(kind, False)(given(case=strategy)(body))
    big = _fuzz_settings(kind, True)(given(case=strategy)(body))
    # Run only when asked for (-m fuzz), even if the marker is not deselected by default.
    big = pytest.mark.skipif("'fuzz' not in (config.getoption('markexpr') or '')",
                             reason="large fuzz budget: run with -m fuzz")(big)
    return fast, pytest.mark.fuzz(big)


# ------------------------------------------------------------------------------ scenarios

scenario_cases = st.sampled_from(sorted(SCENARIO_TEXTS)).flatmap(
    lambda name: st.tuples(st.just(name), mutated(SCENARIO_TEXTS[name]),
                           st.sampled_from(["rrt", "rrt", "rrt", "fuzzy-rrt"])))


def check_scenario_outcome(path: Path, planner: str = "rrt", max_iter: int = 300) -> None:
    """Plan ``path``; assert the contract (clean rejection, or a complete and safe result)."""
    tmp = path.parent
    out = tmp / "result.json"
    code, _, err = run_main(["plan", path, "--planner", planner, "--seed", "1",
                             "--max-iter", str(max_iter), "--out", out])
    if code == 2:
        assert_rejected_cleanly(code, err, path, one_line=True)
        only_inputs_left(tmp, {path.name})
        return
    assert code in (0, 1), err
    # exit 1 says why in one line ("no path: ..." or "not certified: ..."); nothing else but
    # warnings
    # (the first-compile notice is a legitimate line: a mutated scenario may need a kernel
    # signature the warm-up did not compile)
    lines = [x for x in err.splitlines() if x != "compiling planners, first run only…"]
    reasons = [x for x in lines if x.startswith(("no path: ", "not certified: "))]
    assert all(x.startswith("warning: ") for x in lines if x not in reasons), err
    assert len(reasons) == (1 if code == 1 else 0), err
    import json

    result = json.loads(out.read_text())
    only_inputs_left(tmp, {path.name, out.name})
    if code == 0:
        oracle = Oracle(path)
        assert result["success"] is True
        if len(oracle.circles) + len(oracle.boxes) <= 50:
            problems = oracle.path_problems(np.array(result["path_deg"]), resolution_deg=0.1)
            assert problems == [], problems


def _scenario_body(case):
    name, data, planner = case
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / name
        path.write_bytes(data)
        check_scenario_outcome(path, planner)


test_fuzzed_scenarios_are_planned_or_rejected_cleanly, \
    test_fuzzed_scenarios_are_planned_or_rejected_cleanly_large_budget = _two_budgets(
        "scenario", scenario_cases, _scenario_body)


# ------------------------------------------------------------------------------ rulebooks

rulebook_cases = st.sampled_from(RULEBOOK_FILES).flatmap(
    lambda name: st.tuples(st.just(name), mutated(RULEBOOK_TEXTS[name]),
                           st.sampled_from(["lint", "export", "eval"])))

EVAL_INPUT = ("angle_to_goal,dist_to_goal,angle_to_obstacle,dist_to_obstacle\n"
              "0.5,0.1,3.0,0.05\n6.0,0.7,0.0,-1.0\n")


def _rulebook_body(case):
    name, data, command = case
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rb = tmp / "rb"
        shutil.copytree(EXPERT, rb)
        (rb / name).write_bytes(data)
        before = {p.name: p.read_bytes() for p in rb.iterdir()}
        if command == "lint":
            code, _, err = run_main(["rules", "lint", rb])
            outputs = set()
        elif command == "export":
            code, _, err = run_main(["rules", "export", rb, "--format", "fll", "--out", tmp / "fll"])
            outputs = {"fll"}
        else:
            (tmp / "in.csv").write_text(EVAL_INPUT)
            code, _, err = run_main(["rules", "eval", rb, "--input", tmp / "in.csv",
                                     "--output", tmp / "out.csv"])
            outputs = {"out.csv"}
        # A rulebook is never modified by reading it.
        assert {p.name: p.read_bytes() for p in rb.iterdir()} == before
        inputs = {"rb", "in.csv"} if command == "eval" else {"rb"}
        if code == 2:
            assert_rejected_cleanly(code, err, rb, one_line=False)
            only_inputs_left(tmp, inputs)
        else:
            assert code == 0, err
            only_inputs_left(tmp, inputs | outputs)
            if command == "export":
                assert len(list((tmp / "fll").glob("*.fll"))) == 6


test_fuzzed_rulebooks_are_read_or_rejected_cleanly, \
    test_fuzzed_rulebooks_are_read_or_rejected_cleanly_large_budget = _two_budgets(
        "rulebook", rulebook_cases, _rulebook_body)


# ------------------------------------------------------------------------ FLL for import

fll_cases = st.sampled_from(sorted(FLL_TEXTS)).flatmap(
    lambda name: st.tuples(st.just(name), mutated(FLL_TEXTS[name])))


def _fll_body(case):
    name, data = case
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        src = tmp / "fll"
        src.mkdir()
        for n, text in FLL_TEXTS.items():
            (src / n).write_bytes(data if n == name else text)
        out = tmp / "rb"
        code, _, err = run_main(["rules", "import", src, "--out", out])
        if code == 2:
            assert_rejected_cleanly(code, err, src, one_line=False)
            only_inputs_left(tmp, {"fll"})
        else:
            assert code == 0, err
            # What was written is a valid rulebook.
            lint_code, _, lint_err = run_main(["rules", "lint", out])
            assert lint_code == 0, lint_err


test_fuzzed_fll_files_are_imported_or_rejected_cleanly, \
    test_fuzzed_fll_files_are_imported_or_rejected_cleanly_large_budget = _two_budgets(
        "fll", fll_cases, _fll_body)


# ------------------------------------------------------------------- values at the edges

BASE_SCENARIO = """name = "edge"
[arm]
links = {links}
base = {base}
link_radius = {link_radius}
joint_limits_deg = {limits}
[start]
q_deg = {start}
[goal]
q_deg = {goal}
{obstacles}
"""
DEFAULTS = dict(links="[0.2, 0.1]", base="[0.0, 0.0]", link_radius="0.005",
                limits="[[-170.0, 170.0], [-160.0, 160.0]]", start="[-120.0, 30.0]",
                goal="[150.0, -60.0]",
                obstacles='[[obstacles]]\ntype = "circle"\ncenter = [0.26, 0.0]\nradius = 0.04\n'
                          '[[obstacles]]\ntype = "box"\nmin = [-0.1, 0.2]\nmax = [0.0, 0.3]\n')


def scenario_text(**fields) -> str:
    return BASE_SCENARIO.format(**{**DEFAULTS, **fields})


def circles(centres_radii) -> str:
    return "".join(f'[[obstacles]]\ntype = "circle"\ncenter = [{x!r}, {y!r}]\nradius = {r!r}\n'
                   for x, y, r in centres_radii)


def _ring(n: int, distance: float, radius: float) -> str:
    """``n`` circles on a ring around the base: they enclose it without touching the arm."""
    return circles((distance * math.cos(2 * math.pi * k / n), distance * math.sin(2 * math.pi * k / n),
                    radius) for k in range(n))


# (id, fields, expected) with expected "reject:<fragment of the error line>" or "accept".
EDGE_CASES = []
for field, template in [("links", "[{v}, 0.1]"), ("base", "[{v}, 0.0]"), ("link_radius", "{v}"),
                        ("limits", "[[{v}, 170.0], [-160.0, 160.0]]"), ("start", "[{v}, 30.0]"),
                        ("goal", "[150.0, {v}]")]:
    for v in ("nan", "inf", "-inf"):
        EDGE_CASES.append((f"{field}-{v}", {field: template.format(v=v)}, "reject:must be finite"))
EDGE_CASES += [
    ("circle-center-nan", {"obstacles": circles([(math.nan, 0.0, 0.04)]).replace("nan", "nan")},
     "reject:must be finite"),
    ("box-max-inf", {"obstacles": '[[obstacles]]\ntype = "box"\nmin = [0.5, 0.5]\nmax = [inf, 0.6]\n'},
     "reject:must be finite"),
    ("links-1e308", {"links": "[1e308, 1e308]"}, "reject:arm.links[0]: must lie within"),
    ("center-1e308", {"obstacles": circles([(1e308, 0.0, 1.0)])}, "reject:obstacles[0].center[0]"),
    ("radius-1e308", {"obstacles": circles([(0.5, 0.5, 1e308)])}, "reject:obstacles[0].radius"),
    ("box-min--1e308", {"obstacles": '[[obstacles]]\ntype = "box"\nmin = [-1e308, 0.5]\n'
                                     'max = [0.0, 0.6]\n'}, "reject:obstacles[0].min[0]"),
    ("link-radius-negative-zero", {"link_radius": "-0.0"}, "accept"),
    ("start-negative-zero", {"start": "[-0.0, -0.0]", "obstacles": ""}, "accept"),
    ("radius-negative-zero", {"obstacles": circles([(0.5, 0.5, -0.0)])},
     "reject:obstacles[0].radius: must be > 0"),
    ("links-empty", {"links": "[]", "start": "[]", "goal": "[]", "limits": "[]"},
     "reject:arm.links: must list at least one link"),
    ("base-empty", {"base": "[]"}, "reject:arm.base: must have 2 numbers"),
    ("start-empty", {"start": "[]"}, "reject:start.q_deg: must have one angle per link"),
    ("limits-empty", {"limits": "[]"}, "reject:arm.joint_limits_deg: must have one"),
    ("center-empty", {"obstacles": '[[obstacles]]\ntype = "circle"\ncenter = []\nradius = 0.1\n'},
     "reject:obstacles[0].center: must have 2 numbers"),
    # after the [goal] header this key belongs to [goal]: a misplaced key is an error, not
    # silently ignored (an explicit top-level 'obstacles = []' is accepted: test_scenario_loading)
    ("obstacles-key-inside-goal", {"obstacles": "obstacles = []"},
     "reject:unknown key 'obstacles' in [goal]"),
    ("links-1e-9", {"links": "[1e-9, 1e-9]", "link_radius": "0.0"}, "accept"),
    # found by the fuzzer: subnormal links squared to 0 and divided by zero in the planner
    ("links-subnormal", {"links": "[5e-324, 5e-324]"},
     "reject:arm.links[0]: link length must be at least 1e-09 m"),
    ("start-on-joint-limits", {"start": "[-170.0, 160.0]", "goal": "[170.0, -160.0]",
                               "obstacles": circles([(0.0, 0.5, 0.05)])}, "accept"),
    ("limits-wider-than-a-turn", {"limits": "[[-190.0, 170.0], [-160.0, 160.0]]"},
     "reject:must lie within [-180, 180]"),
    ("box-enclosing-the-base", {"obstacles": '[[obstacles]]\ntype = "box"\nmin = [-1.0, -1.0]\n'
                                             'max = [1.0, 1.0]\n'},
     "reject:start.q_deg: configuration"),
    ("circles-enclosing-the-arm", {"obstacles": _ring(24, 0.4, 0.06)}, "accept"),
    ("q-deg-huge-integer", {"start": "[" + "9" * 400 + ", 30.0]"}, "reject:start.q_deg[0]"),
    ("q-deg-string", {"start": '["-120", 30.0]'}, "reject:start.q_deg[0]: must be a number"),
    ("q-deg-boolean", {"goal": "[true, 0.0]"}, "reject:goal.q_deg[0]: must be a number"),
]


@pytest.mark.parametrize("case_id,fields,expected", EDGE_CASES, ids=[c[0] for c in EDGE_CASES])
def test_scenario_edge_values_are_planned_safely_or_rejected_with_the_key(
        tmp_path, case_id, fields, expected):
    path = tmp_path / f"{case_id}.toml"
    path.write_text(scenario_text(**fields))
    code, _, err = run_main(["plan", path, "--planner", "rrt", "--max-iter", "2000",
                             "--out", tmp_path / "result.json"])
    if expected == "accept":
        assert code in (0, 1), err
        check_scenario_outcome(path)  # and the path, if any, is collision-free
    else:
        assert_rejected_cleanly(code, err, path, one_line=True)
        assert expected.split(":", 1)[1] in err, err
        only_inputs_left(tmp_path, {path.name})


def crowd_of_ten_thousand(seed: int = 0) -> list[tuple[float, float, float]]:
    """10,000 small circles far beyond the arm's reach (shared with the benchmark
    ``benchmarks/test_bench_crowd.py``, which times planning among them)."""
    rng = random.Random(seed)
    return [(rng.uniform(-50, 50), rng.uniform(2, 50), 0.1) for _ in range(10_000)]


@pytest.mark.slow
def test_ten_thousand_obstacles_are_planned_to_a_safe_result(tmp_path):
    """Behaviour only: the plan completes and whatever it returns is certified (its speed,
    21.6 s alone and over 30 s under load, is a benchmark's business, not a pass/fail)."""
    import json

    path = tmp_path / "crowd.toml"
    path.write_text(scenario_text(obstacles=circles(crowd_of_ten_thousand())))
    code, _, err = run_main(["plan", path, "--planner", "rrt", "--max-iter", "200",
                             "--out", tmp_path / "result.json"], limit=False)
    assert code in (0, 1), err
    result = json.loads((tmp_path / "result.json").read_text())
    assert result["success"] == (result["found"] and result["certified"])
    assert not result["penetration_m"]  # 0 or none: nothing penetrated
    if result["found"]:
        assert result["certified"] and result["min_clearance_m"] > 0
    assert code == (0 if result["success"] else 1)
    only_inputs_left(tmp_path, {path.name, "result.json"})


def test_ten_thousand_obstacles_one_on_the_start_is_rejected_with_its_key(tmp_path):
    rng = random.Random(1)
    crowd = [(rng.uniform(-50, 50), rng.uniform(2, 50), 0.1) for _ in range(9_999)]
    path = tmp_path / "crowd.toml"
    path.write_text(scenario_text(obstacles=circles(crowd + [(0.0, 0.0, 0.01)])))
    code, _, err = run_main(["plan", path, "--planner", "rrt", "--out", tmp_path / "r.json"])
    assert_rejected_cleanly(code, err, path, one_line=True)
    assert "start.q_deg: configuration" in err


# -------------------------------------------------------- bugs found by fuzzing, pinned


def test_deeply_nested_scenario_toml_is_a_syntax_error_not_a_crash(tmp_path):
    path = tmp_path / "deep.toml"
    path.write_text('name = "deep"\n[arm]\nlinks = ' + "[" * 100_000 + "]" * 100_000 + "\n")
    code, _, err = run_main(["plan", path, "--planner", "rrt"])
    assert_rejected_cleanly(code, err, path, one_line=True)
    assert "nested too deeply" in err


def test_deeply_nested_rulebook_manifest_is_a_lint_error_not_a_crash(tmp_path):
    rb = tmp_path / "rb"
    shutil.copytree(EXPERT, rb)
    with open(rb / "rulebook.toml", "a") as fh:
        fh.write("x = " + "[" * 100_000 + "]" * 100_000 + "\n")
    code, _, err = run_main(["rules", "lint", rb])
    assert_rejected_cleanly(code, err, rb, one_line=True)
    assert "nested too deeply" in err


def test_geometry_too_large_for_float64_is_rejected_before_it_can_fool_the_check(tmp_path):
    """1e160 m links used to overflow the squared distances to inf, and the certified check
    then 'certified' a sweep straight through a box in one infinite step."""
    from single_arm import edge_free

    links, base = np.array([1e160]), np.zeros(2)
    box = np.array([[1.0, 2e159, -1.0, 3e159, 1.0]])  # on the x axis, crossed at q = 0
    assert not edge_free(links, base, 0.0, box, np.array([45.0]), np.array([-45.0]), 1e-6)
    path = tmp_path / "huge.toml"
    path.write_text(scenario_text(links="[1e160]", start="[45.0]", goal="[-45.0]",
                                  limits="[[-90.0, 90.0]]",
                                  obstacles='[[obstacles]]\ntype = "box"\nmin = [2e159, -1.0]\n'
                                            'max = [3e159, 1.0]\n'))
    code, _, err = run_main(["plan", path, "--planner", "rrt"])
    assert_rejected_cleanly(code, err, path, one_line=True)
    assert "arm.links[0]: must lie within" in err


def _fll_dir(tmp: Path, edit=None) -> Path:
    src = tmp / "fll"
    src.mkdir()
    for n, text in FLL_TEXTS.items():
        (src / n).write_bytes(edit(text) if edit else text)
    return src


@pytest.mark.parametrize("description", ['[1, 2]', '"a string"', "null", "3",
                                         '{"name": "  ", "bounds_mode": "relative"}',
                                         '{"name": 7}', "[" * 100_000])
def test_fll_description_that_is_not_a_usable_object_is_ignored(tmp_path, description):
    src = _fll_dir(tmp_path, lambda t: re.sub(rb"description: xfuzzy-rrt .*",
                                              b"description: xfuzzy-rrt " + description.encode(), t))
    code, out, err = run_main(["rules", "import", src, "--out", tmp_path / "rb"])
    assert code == 0, err
    assert "wrote rulebook 'fll'" in out  # the directory name, not a blank or odd meta name


def test_blank_import_name_is_a_usage_error(tmp_path):
    src = _fll_dir(tmp_path)
    code, _, err = run_main(["rules", "import", src, "--out", tmp_path / "rb", "--name", "  "])
    assert code == 2 and err == "error: --name: must be a non-empty rulebook name\n"
    only_inputs_left(tmp_path, {"fll"})


@pytest.mark.parametrize("command", ["plan-out-dir", "plan-out-under-file", "export-out-file",
                                     "import-out-file", "bench-out-file"])
def test_output_path_that_cannot_be_written_is_one_error_line(tmp_path, command, monkeypatch):
    if command == "bench-out-file":  # refused before any planning starts
        import xfuzzy_rrt.bench.runner as runner

        def no_planning(*a, **k):
            raise AssertionError("bench planned although --out cannot be written")

        monkeypatch.setattr(runner, "run_benchmark", no_planning)
    scenario = FIXTURES / "scenarios" / "two-circles.toml"
    (tmp_path / "adir").mkdir()
    (tmp_path / "afile").write_text("keep me")
    args = {
        "plan-out-dir": ["plan", scenario, "--planner", "rrt", "--out", tmp_path / "adir"],
        "plan-out-under-file": ["plan", scenario, "--planner", "rrt", "--out",
                                tmp_path / "afile" / "r.json"],
        "export-out-file": ["rules", "export", EXPERT, "--format", "fll", "--out",
                            tmp_path / "afile"],
        "import-out-file": ["rules", "import", _fll_dir(tmp_path), "--out", tmp_path / "afile"],
        "bench-out-file": ["bench", scenario, "--planners", "rrt", "--runs", "1", "--out",
                           tmp_path / "afile"],
    }[command]
    code, _, err = run_main(args)
    where = tmp_path / ("adir" if command == "plan-out-dir" else "afile")
    assert_rejected_cleanly(code, err, where, one_line=True)
    assert (tmp_path / "afile").read_text() == "keep me"
    assert list((tmp_path / "adir").iterdir()) == []
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


# --------------------------------------------------------- through the real console script

CONSOLE_CASES = [  # (kind, seed): a deterministic mutation of each kind and level
    ("scenario", 1), ("scenario", 2), ("rulebook", 3), ("rulebook", 4), ("fll", 5), ("fll", 6)]


def _deterministic_mutation(data: bytes, seed: int) -> bytes:
    rng = random.Random(seed)
    text = data.decode("utf-8")
    level = seed % 3
    if level == 0:  # bytes: a flipped byte and a truncation
        b = bytearray(data)
        b[rng.randrange(len(b))] ^= 0x80
        return bytes(b[: rng.randrange(len(b) // 2, len(b))])
    if level == 1:  # tokens: a keyword replaced by another
        toks = _TOKEN.findall(text)
        words = [i for i, t in enumerate(toks) if t.strip()]
        toks[rng.choice(words)] = rng.choice(TOKENS)
        return "".join(toks).encode("utf-8")
    spans = [m.span() for m in _NUMBER.finditer(text)]  # values
    a, b = rng.choice(spans)
    return (text[:a] + rng.choice(["nan", "inf", "1e308", "-0.0", "[]"]) + text[b:]).encode()


@pytest.mark.parametrize("kind,seed", CONSOLE_CASES)
def test_mutated_inputs_through_the_console_script_follow_the_contract(run_cli, tmp_path, kind,
                                                                       seed):
    if kind == "scenario":
        target = tmp_path / "s.toml"
        target.write_bytes(_deterministic_mutation(SCENARIO_TEXTS["two-circles.toml"], seed))
        args, out = ["plan", target, "--planner", "rrt", "--out", tmp_path / "o.json"], "o.json"
        inputs = {"s.toml"}
    elif kind == "rulebook":
        target = tmp_path / "rb"
        shutil.copytree(EXPERT, target)
        name = ["goal_bias.fis", "rulebook.toml"][seed % 2]
        (target / name).write_bytes(_deterministic_mutation(RULEBOOK_TEXTS[name], seed))
        args, out, inputs = ["rules", "export", target, "--out", tmp_path / "x"], "x", {"rb"}
    else:
        target = tmp_path / "fll"
        target.mkdir()
        for n, text in FLL_TEXTS.items():
            (target / n).write_bytes(_deterministic_mutation(text, seed) if n == "step_size.fll"
                                     else text)
        args, out, inputs = ["rules", "import", target, "--out", tmp_path / "rb"], "rb", {"fll"}
    proc = run_cli(*args, timeout=120)
    assert "Traceback" not in proc.stderr
    if proc.returncode == 2:
        assert_rejected_cleanly(2, proc.stderr, target, one_line=(kind == "scenario"))
        only_inputs_left(tmp_path, inputs)
    else:
        assert proc.returncode in (0, 1), proc.stderr
        only_inputs_left(tmp_path, inputs | {out})
