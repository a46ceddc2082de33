"""Export to and import from fuzzylite's FLL format (one ``Engine`` per output FIS).

Why: FLL is the lingua franca of fuzzylite/pyfuzzylite/QtFuzzyLite, so a rulebook can be
checked, plotted or reused with an outside tool, and an outside tool can supply a rulebook.
The export follows the "FLL interop notes" in SPEC.md, which record what pyfuzzylite 8
actually computes:

- four ``InputVariable`` with ``lock-range: true`` (pyfuzzylite then clamps inputs to the
  range, as our engine does); terms: the left shoulder as ``Ramp p1 lo``, the triangles as
  ``Triangle a b c``, the right shoulder as ``Ramp p3 hi``;
- one ``OutputVariable`` with ``aggregation: none`` and ``defuzzifier: WeightedAverage
  TakagiSugeno`` and one ``Constant`` term ``rN`` per rule (pyfuzzylite merges rules that
  share a term under ``Maximum``/``AlgebraicSum`` aggregation, which would be wrong);
- a ``RuleBlock`` with ``conjunction: AlgebraicProduct``, ``activation: General``;
- every number with 17 significant digits (``%.17g``): exact for float64, whereas
  pyfuzzylite's own default of 3 decimals moves outputs by ~3e-3.

The ``Engine``'s ``description`` line carries the rulebook name, bounds mode and sha256 so an
import can restore them. :func:`import_fll` reads this subset back (terms may come in any
order and shoulders may also be ``Triangle -inf lo p1`` / ``Triangle p3 hi inf``), checks that
the terms form the Ruspini partition the engine assumes, and reports every problem with file
and line. Export followed by import gives identical arrays.

Rulebooks written in the compact layout (rules with ``any`` terms, see :mod:`.text_format`)
export exactly like their full form: the model is always the expanded 625-constant grid, so
the FLL files always hold 625 fully specified rules (FLL has no don't-care term that
pyfuzzylite evaluates the same way), and a compact rulebook and its full form export to
identical bytes.
"""

from __future__ import annotations

import datetime as dt
import json
import math
import os
import re
from pathlib import Path

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, write_files
from xfuzzy_rrt.fuzzy.system import FuzzySystem, InputPartition, peaks_problem, term_name_problem
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import N_RULES, N_TERMS, rule_index, rule_terms

FLL_SUFFIX = ".fll"
_DESCRIPTION_TAG = "xfuzzy-rrt"

Problem = tuple[str, "int | None", str]


def num(v: float) -> str:
    """17 significant digits: exact for any float64 and read back bit-identically."""
    return f"{float(v):.17g}"


def fll_file_name(output: str) -> str:
    return output + FLL_SUFFIX


# ---------------------------------------------------------------------------- export


def format_fll(fis: FuzzySystem, rulebook: Rulebook | None = None) -> str:
    """FLL text of one FIS (an ``Engine`` named after its output)."""
    lines = [f"# xfuzzy-rrt export of FIS {fis.output} (pyfuzzylite 8 compatible)"]
    lines.append(f"Engine: {fis.output}")
    if rulebook is not None:
        meta = {"name": rulebook.name, "bounds_mode": rulebook.bounds_mode, "sha256": rulebook.sha256}
        if rulebook.semantics.name != "paper":
            meta["semantics"] = rulebook.semantics.name
        if rulebook.dof != _sem.DEFAULT_DOF:  # 2-DOF exports keep their bytes
            meta["dof"] = rulebook.dof
        lines.append(f"  description: {_DESCRIPTION_TAG} {json.dumps(meta, sort_keys=True)}")
    for inp in fis.inputs:
        lo, p1, p2, p3, hi = inp.peaks
        t = inp.terms
        lines += [
            f"InputVariable: {inp.name}",
            "  enabled: true",
            f"  range: {num(lo)} {num(hi)}",
            "  lock-range: true",
            f"  term: {t[0]} Ramp {num(p1)} {num(lo)}",
            f"  term: {t[1]} Triangle {num(lo)} {num(p1)} {num(p2)}",
            f"  term: {t[2]} Triangle {num(p1)} {num(p2)} {num(p3)}",
            f"  term: {t[3]} Triangle {num(p2)} {num(p3)} {num(hi)}",
            f"  term: {t[4]} Ramp {num(p3)} {num(hi)}",
        ]
    lo, hi = fis.range
    lines += [
        f"OutputVariable: {fis.output}",
        "  enabled: true",
        f"  range: {num(lo)} {num(hi)}",
        "  lock-range: false",
        "  aggregation: none",
        "  defuzzifier: WeightedAverage TakagiSugeno",
        "  default: nan",
        "  lock-previous: false",
    ]
    lines += [f"  term: r{r} Constant {num(c)}" for r, c in enumerate(fis.consts)]
    lines += [
        "RuleBlock: rules",
        "  enabled: true",
        "  conjunction: AlgebraicProduct",
        "  disjunction: none",
        "  implication: none",
        "  activation: General",
    ]
    for r in range(N_RULES):
        t = rule_terms(r)
        ante = " and ".join(f"{inp.name} is {inp.terms[t[i]]}" for i, inp in enumerate(fis.inputs))
        lines.append(f"  rule: if {ante} then {fis.output} is r{r}")
    return "\n".join(lines) + "\n"


def export_fll(rulebook: Rulebook, out_dir: str | os.PathLike[str]) -> list[Path]:
    """Write ``<output>.fll`` for each FIS (six at 2 DOF) into *out_dir*; return the paths."""
    texts = {fll_file_name(s.output): format_fll(s, rulebook) for s in rulebook.systems}
    root = write_files(out_dir, texts)
    return [root / name for name in texts]


# ---------------------------------------------------------------------------- import


class _Var:
    def __init__(self, kind: str, name: str, line: int) -> None:
        self.kind, self.name, self.line = kind, name, line
        self.props: dict[str, tuple[int, str]] = {}
        self.terms: list[tuple[int, str, str, list[str]]] = []  # (line, name, type, params)


def _float(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _peak_of(ttype: str, params: list[float]) -> tuple[float, float, float] | None:
    """``(left foot, peak, right foot)`` of a supported term, ``None`` if unsupported."""
    if ttype == "Triangle" and len(params) == 3:
        return params[0], params[1], params[2]
    if ttype == "Ramp" and len(params) == 2:
        start, end = params
        if start > end:  # falling: 1 at end (left shoulder)
            return -math.inf, end, start
        if start < end:  # rising: 1 at end (right shoulder)
            return start, end, math.inf
    return None


def parse_fll(data: bytes, file: str, expected_output: str,
              sem: "_sem.Semantics" = None) -> tuple[FuzzySystem | None, dict, list[Problem]]:
    """Parse one exported-style FLL engine into a FIS. Returns (fis or None, meta, problems)."""
    sem = sem or _sem.PAPER
    problems: list[Problem] = []

    def problem(line: int | None, msg: str) -> None:
        problems.append((file, line, msg))

    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        return None, {}, [(file, data[: exc.start].count(b"\n") + 1, "not valid UTF-8")]
    meta: dict = {}
    engine_name: tuple[int, str] | None = None
    variables: list[_Var] = []
    block: dict[str, tuple[int, str]] = {}
    rules: list[tuple[int, str]] = []
    section = None
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        key, sep, value = line.partition(":")
        key, value = key.strip(), value.strip()
        if not sep:
            problem(n, f"expected 'key: value', got {line[:60]!r}")
            continue
        if key == "Engine":
            engine_name = (n, value)
            section = "Engine"
        elif key in ("InputVariable", "OutputVariable"):
            variables.append(_Var(key, value, n))
            section = "var"
        elif key == "RuleBlock":
            section = "RuleBlock"
        elif section == "Engine" and key == "description":
            if value.startswith(_DESCRIPTION_TAG + " "):
                try:
                    meta = json.loads(value[len(_DESCRIPTION_TAG) + 1:])
                except (json.JSONDecodeError, RecursionError):
                    meta = {}
                if not isinstance(meta, dict):  # only an object carries name, mode, sha256
                    meta = {}
        elif section == "var" and key == "term":
            parts = value.split()
            if len(parts) < 2:
                problem(n, "expected 'term: NAME TYPE PARAMETERS...'")
                continue
            variables[-1].terms.append((n, parts[0], parts[1], parts[2:]))
        elif section == "var":
            variables[-1].props[key] = (n, value)
        elif section == "RuleBlock" and key == "rule":
            rules.append((n, value))
        elif section == "RuleBlock":
            block[key] = (n, value)
        elif section is None:
            problem(n, f"{key!r} before any 'Engine:' section")
    if engine_name is None:
        problem(1, "no 'Engine:' section")

    inputs = {v.name: v for v in variables if v.kind == "InputVariable"}
    outputs = [v for v in variables if v.kind == "OutputVariable"]
    for v in variables:
        if v.kind == "InputVariable" and v.name not in sem.inputs:
            problem(v.line, f"unknown input variable {v.name!r} (inputs: {', '.join(sem.inputs)})")
    for name in sem.inputs:
        if name not in inputs:
            problem(engine_name[0] if engine_name else 1, f"missing InputVariable {name!r}")
    if len(outputs) != 1:
        problem(engine_name[0] if engine_name else 1, f"expected one OutputVariable, found {len(outputs)}")
    elif outputs[0].name != expected_output:
        problem(outputs[0].line, f"wrong output variable {outputs[0].name!r}: this file describes {expected_output!r}")

    # engine semantics we can represent
    for key, allowed in (("conjunction", {"AlgebraicProduct"}), ("activation", {"General"})):
        if key in block and block[key][1] not in allowed:
            problem(block[key][0], f"{key} {block[key][1]!r} is not supported (xfuzzy-rrt uses {', '.join(sorted(allowed))})")
    if outputs:
        out = outputs[0]
        agg = out.props.get("aggregation")
        if agg and agg[1] != "none":
            problem(agg[0], f"aggregation {agg[1]!r} is not supported (needs 'none'; merged rules would change the result)")
        dfz = out.props.get("defuzzifier")
        if dfz and dfz[1].split()[0] != "WeightedAverage":
            problem(dfz[0], f"defuzzifier {dfz[1]!r} is not supported (needs WeightedAverage)")

    def check_range(v: _Var, expected: tuple[float, float], earlier=()) -> tuple[float, float]:
        """Check *v*'s declared range (today's, or one in *earlier*); return the range its
        values must keep to (the declared one when it is valid, else *expected*)."""
        rng = v.props.get("range")
        if rng is None:
            problem(v.line, f"{v.name}: missing range")
            return expected
        vals = [_float(x) for x in rng[1].split()]
        if len(vals) != 2 or (tuple(vals) != expected and tuple(vals) not in earlier):
            problem(rng[0], f"range of {v.name} must be {num(expected[0])} {num(expected[1])}, got {rng[1]}")
            return expected
        return (vals[0], vals[1])

    partitions: dict[str, InputPartition] = {}
    for name in sem.inputs:
        v = inputs.get(name)
        if v is None:
            continue
        check_range(v, sem.input_ranges[name])
        part = _partition(v, problem, sem)
        if part is not None:
            partitions[name] = part

    consts: list[float | None] = [None] * N_RULES
    if outputs and outputs[0].name == expected_output:
        out = outputs[0]
        lo, hi = check_range(out, sem.output_ranges[expected_output],
                             sem.earlier_output_ranges.get(expected_output, ()))
        values: dict[str, float] = {}
        for n, tname, ttype, params in out.terms:
            value = _float(params[0]) if ttype == "Constant" and len(params) == 1 else None
            if value is None or not math.isfinite(value):
                problem(n, f"output term {tname!r} must be 'Constant VALUE' with a finite value")
                continue
            if not lo <= value <= hi:
                problem(n, f"constant {params[0]} outside the output range [{lo!r}, {hi!r}]")
                continue
            values[tname] = value
        if len(partitions) == len(sem.inputs):
            seen: dict[int, int] = {}
            rule_re = re.compile(r"if\s+(.+?)\s+then\s+(\S+)\s+is\s+(\S+)(?:\s+with\s+(\S+))?\Z")
            for n, rtext in rules:
                m = rule_re.match(" ".join(rtext.split()))
                if not m:
                    problem(n, "malformed rule (expected 'if A is T and ... then OUT is TERM')")
                    continue
                if m.group(4) is not None and _float(m.group(4)) != 1.0:
                    problem(n, "rule weights other than 1 are not supported")
                    continue
                by_var = {}
                ok = True
                for clause in re.split(r"\s+and\s+", m.group(1)):
                    cm = re.fullmatch(r"(\S+)\s+is\s+(\S+)", clause)
                    if not cm or cm.group(1) not in partitions or cm.group(1) in by_var:
                        problem(n, f"unsupported condition {clause!r} (need each input once: 'INPUT is TERM')")
                        ok = False
                        break
                    terms = partitions[cm.group(1)].terms
                    if cm.group(2) not in terms:
                        problem(n, f"unknown term {cm.group(2)!r} for {cm.group(1)}")
                        ok = False
                        break
                    by_var[cm.group(1)] = terms.index(cm.group(2))
                if not ok:
                    continue
                if len(by_var) != len(sem.inputs):
                    problem(n, "every rule must name all four inputs")
                    continue
                if m.group(2) != expected_output or m.group(3) not in values:
                    problem(n, f"consequent '{m.group(2)} is {m.group(3)}' is not a Constant term of {expected_output}")
                    continue
                r = rule_index([by_var[name] for name in sem.inputs])
                if r in seen:
                    problem(n, f"duplicate rule: same conditions as line {seen[r]}")
                    continue
                seen[r] = n
                consts[r] = values[m.group(3)]
            missing = [r for r in range(N_RULES) if consts[r] is None]
            if missing:
                problem(None, f"{len(missing)} of {N_RULES} rules missing (first: r{missing[0]})")
    if problems:
        return None, meta, problems
    fis = FuzzySystem(
        output=expected_output,
        inputs=tuple(partitions[name] for name in sem.inputs),
        consts=tuple(consts),
        dof=sem.dof,
    )
    return fis, meta, []


def _partition(v: _Var, problem, sem: "_sem.Semantics") -> InputPartition | None:
    """The five terms of an input as a Ruspini partition, or ``None`` (problems reported)."""
    if len(v.terms) != N_TERMS:
        problem(v.line, f"{v.name}: expected {N_TERMS} terms, got {len(v.terms)}")
        return None
    shapes = []
    for n, tname, ttype, params in v.terms:
        vals = [_float(p) for p in params]
        shape = None if any(x is None for x in vals) else _peak_of(ttype, vals)
        bad_name = term_name_problem(tname)
        if bad_name:
            problem(n, bad_name)
            return None
        if shape is None:
            problem(n, f"term {tname!r}: only Triangle and Ramp terms are supported, got {ttype} {' '.join(params)}")
            return None
        shapes.append((shape[1], shape, tname, n))
    seen = {}
    for _, _, tname, n in shapes:
        if tname in seen:  # rules name terms, so two of one name cannot both be meant
            problem(n, f"{v.name}: term {tname!r} is named twice (also on line {seen[tname]}); "
                       "term names must be distinct")
            return None
        seen[tname] = n
    shapes.sort(key=lambda s: s[0])
    lo, hi = sem.input_ranges[v.name]
    peaks = [s[0] for s in shapes]
    # infinite shoulders: -inf / +inf feet are fine at the ends
    problem_text = peaks_problem(tuple(peaks), lo, hi)
    if problem_text:
        problem(v.line, f"{v.name}: {problem_text}")
        return None
    for j, (peak, (left, _, right), tname, n) in enumerate(shapes):
        want_left = peaks[j - 1] if j > 0 else None
        want_right = peaks[j + 1] if j < N_TERMS - 1 else None
        ok_left = left == want_left if want_left is not None else (left == -math.inf or left == peak)
        ok_right = right == want_right if want_right is not None else (right == math.inf or right == peak)
        if not (ok_left and ok_right):
            problem(n, f"term {tname!r} does not fit a Ruspini partition (feet must be the neighbouring peaks)")
            return None
    return InputPartition(name=v.name, terms=tuple(s[2] for s in shapes), peaks=tuple(peaks),
                          dof=sem.dof)


_BOUND_FLL = re.compile(r"bound_([1-9][0-9]*)\Z")


def _infer_dof(root: Path, sem: "_sem.Semantics", problems: list) -> int:
    """The DOF of the engines in *root* (2 when nothing says otherwise; problems reported).

    Paper: the ``bound_K.fll`` files present must be exactly ``bound_1 … bound_2N`` for one N.
    Goal-frame: ``joint_dist_to_goal``'s range in ``goal_bias.fll`` is ``[0, 180*sqrt(2N)]``.
    """
    if sem.name == _sem.PAPER.name:
        bounds = sorted((p.stem for p in root.glob("bound_*" + FLL_SUFFIX) if _BOUND_FLL.match(p.stem)),
                        key=lambda b: int(_BOUND_FLL.match(b).group(1)))
        dof = _sem.dof_of_outputs(sem.name, [sem.outputs[0], *bounds, sem.outputs[-1]])
        if dof is None:
            problems.append((str(root), None, f"bound files {', '.join(bounds) or '(none)'} fit no "
                             f"DOF: an arm of N joints needs bound_1{FLL_SUFFIX} \u2026 "
                             f"bound_2N{FLL_SUFFIX} (N = {_sem.MIN_DOF}..{_sem.MAX_DOF})"))
            return _sem.DEFAULT_DOF
        return dof
    name = sem.inputs[0]
    if name != "joint_dist_to_goal":  # pragma: no cover - only goal-frame has DOF-free outputs
        return _sem.DEFAULT_DOF
    try:
        text = (root / fll_file_name(sem.outputs[0])).read_text("utf-8", errors="replace")
    except OSError:
        return _sem.DEFAULT_DOF  # the missing file is reported by the caller
    m = re.search(r"InputVariable:\s*" + name + r"\s*\n(?:[^\n]*\n)*?\s*range:\s*(\S+)\s+(\S+)", text)
    got = (_float(m.group(1)), _float(m.group(2))) if m else None
    for d in range(_sem.MIN_DOF, _sem.MAX_DOF + 1):
        if sem.for_dof(d).input_ranges[name] == got:
            return d
    return _sem.DEFAULT_DOF  # a wrong range is reported by parse_fll, against the 2-DOF one


def _names_input(path: Path, name: str) -> bool:
    """Whether the FLL file at *path* declares ``InputVariable: name`` (goal-frame and
    goal-frame-any have the same output files; their input names tell them apart)."""
    try:
        text = path.read_text("utf-8", errors="replace")
    except OSError:
        return False
    return re.search(r"InputVariable:\s*" + re.escape(name) + r"\s*$", text, flags=re.M) is not None


def import_fll(
    fll_dir: str | os.PathLike[str],
    *,
    name: str | None = None,
    bounds_mode: str | None = None,
    command: str | None = None,
) -> Rulebook:
    """Read ``<output>.fll`` for every output from *fll_dir* into a :class:`Rulebook`.

    Name and bounds mode come from the export's description line unless given; otherwise the
    directory name and ``"absolute"`` (the paper's reading). The DOF comes from the files: for
    the paper's semantics from the output names (``bound_1.fll … bound_2N.fll``), for
    goal-frame (whose outputs do not depend on it) from the range of ``joint_dist_to_goal``.
    Raises :class:`RulebookError` with every problem found.
    """
    root = Path(fll_dir)
    if not root.is_dir():
        raise RulebookError([(str(root), None, "FLL directory does not exist or is not a directory")])
    problems: list[Problem] = []
    systems = []
    meta: dict = {}
    # which semantics: the one whose second output's file is present (the first, goal_bias,
    # is shared); the export's description line says it too
    sem = next((s for s in _sem.SEMANTICS.values() if (root / fll_file_name(s.outputs[1])).is_file()
                and _names_input(root / fll_file_name(s.outputs[0]), s.inputs[0])),
               None) or next((s for s in _sem.SEMANTICS.values()
                              if (root / fll_file_name(s.outputs[1])).is_file()), _sem.PAPER)
    sem = sem.for_dof(_infer_dof(root, sem, problems))
    for output in sem.outputs:
        file = root / fll_file_name(output)
        try:
            data = file.read_bytes()
        except OSError as exc:
            problems.append((str(file), None, "missing file" if isinstance(exc, FileNotFoundError) else f"cannot read: {exc}"))
            continue
        fis, file_meta, found = parse_fll(data, str(file), output, sem)
        problems.extend(found)
        systems.append(fis)
        meta = meta or file_meta
    if problems:
        raise RulebookError(problems)
    mode = bounds_mode or meta.get("bounds_mode") or "absolute"
    if sem.name != _sem.PAPER.name:
        mode = None
    elif mode not in ("absolute", "relative"):
        raise RulebookError([(str(root), None, f"bounds mode must be absolute or relative, got {mode!r}")])
    provenance = {
        "kind": "imported-fll",
        "source": str(root),
        "date": dt.datetime.now(dt.timezone.utc).replace(microsecond=0).isoformat(),
    }
    if command:
        provenance["command"] = command
    if meta.get("sha256"):
        provenance["source_sha256"] = str(meta["sha256"])
    meta_name = meta.get("name")
    if not isinstance(meta_name, str) or not meta_name.strip():
        meta_name = None  # a blank or non-text name in a hand-edited export: fall back
    return Rulebook(
        name=name or meta_name or root.resolve().name,
        bounds_mode=mode,
        systems=tuple(systems),
        provenance=provenance,
        semantics=sem,
    )
